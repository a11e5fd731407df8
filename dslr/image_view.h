// A view of an image's values, for the functions that read or write one without owning it:
// `channels` interleaved values a pixel, row after row, width x height pixels.
#pragma once

#include <cstddef>
#include <type_traits>
#include <vector>

namespace rigc::dslr {

template <typename T>
struct ImageView {
  T* values = nullptr;
  int width = 0, height = 0, channels = 3;

  std::size_t pixels() const { return static_cast<std::size_t>(width) * height; }
  std::size_t size() const { return pixels() * channels; }
  bool empty() const { return size() == 0; }
  // A view that only reads.
  operator ImageView<const T>() const requires(!std::is_const_v<T>) {
    return {values, width, height, channels};
  }
};

// `values` as a width x height image of `channels` a pixel; an empty view when the vector does
// not hold exactly that many values.
template <typename T>
ImageView<T> view_of(std::vector<T>& values, int width, int height, int channels = 3) {
  if (width <= 0 || height <= 0 ||
      values.size() != static_cast<std::size_t>(width) * height * channels) {
    return {};
  }
  return {values.data(), width, height, channels};
}

template <typename T>
ImageView<const T> view_of(const std::vector<T>& values, int width, int height, int channels = 3) {
  if (width <= 0 || height <= 0 ||
      values.size() != static_cast<std::size_t>(width) * height * channels) {
    return {};
  }
  return {values.data(), width, height, channels};
}

}  // namespace rigc::dslr
