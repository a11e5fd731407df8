// What each shot sees of the object, kept across coverage analyses of scenes whose geometry is
// the same: the studio's exposure, focus and light changes re-judge the faces without rendering
// their visibility again.
#pragma once

#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

namespace rigc::analysis {

// One shot's sight of the object: which faces it sees (facing it, in front, inside the canvas,
// not hidden) and how much of the visibility buffer shows the object.
struct ShotVisibility {
  std::vector<std::uint8_t> seen;  // per face
  std::size_t object_pixels = 0, pixels = 0;
};

// Shot visibilities by key (the geometry's fingerprint, the poses and the canvas; see
// coverage.cpp). Thread-safe; beyond `capacity_bytes` the least recently used go first.
class VisibilityCache {
 public:
  explicit VisibilityCache(std::size_t capacity_bytes = 64u << 20);

  std::shared_ptr<const ShotVisibility> find(const std::string& key);
  void insert(const std::string& key, std::shared_ptr<const ShotVisibility> visibility);

  std::size_t entries() const;
  std::size_t bytes() const;
  std::size_t hits() const;

 private:
  using Entry = std::pair<std::string, std::shared_ptr<const ShotVisibility>>;
  mutable std::mutex mutex_;
  const std::size_t capacity_bytes_;
  std::size_t bytes_ = 0, hits_ = 0;
  std::list<Entry> recent_;  // most recently used first
  std::unordered_map<std::string, std::list<Entry>::iterator> by_key_;
};

}  // namespace rigc::analysis
