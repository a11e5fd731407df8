#include "analysis/visibility_cache.h"

namespace rigc::analysis {

namespace {

std::size_t size_of(const std::string& key, const ShotVisibility& v) {
  return key.size() + v.seen.size() + sizeof(ShotVisibility);
}

}  // namespace

VisibilityCache::VisibilityCache(std::size_t capacity_bytes) : capacity_bytes_(capacity_bytes) {}

std::shared_ptr<const ShotVisibility> VisibilityCache::find(const std::string& key) {
  std::lock_guard lock(mutex_);
  const auto it = by_key_.find(key);
  if (it == by_key_.end()) return nullptr;
  recent_.splice(recent_.begin(), recent_, it->second);
  ++hits_;
  return it->second->second;
}

void VisibilityCache::insert(const std::string& key,
                             std::shared_ptr<const ShotVisibility> visibility) {
  std::lock_guard lock(mutex_);
  if (by_key_.count(key)) return;
  bytes_ += size_of(key, *visibility);
  recent_.emplace_front(key, std::move(visibility));
  by_key_[key] = recent_.begin();
  while (bytes_ > capacity_bytes_ && recent_.size() > 1) {
    const Entry& oldest = recent_.back();
    bytes_ -= size_of(oldest.first, *oldest.second);
    by_key_.erase(oldest.first);
    recent_.pop_back();
  }
}

std::size_t VisibilityCache::entries() const {
  std::lock_guard lock(mutex_);
  return recent_.size();
}

std::size_t VisibilityCache::bytes() const {
  std::lock_guard lock(mutex_);
  return bytes_;
}

std::size_t VisibilityCache::hits() const {
  std::lock_guard lock(mutex_);
  return hits_;
}

}  // namespace rigc::analysis
