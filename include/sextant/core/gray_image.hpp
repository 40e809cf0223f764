#pragma once
/// \file An 8-bit grayscale image, row-major: what the globe renderer (sim/globe_render.hpp) draws
/// and the front-end (vision/gray_image_view.hpp) reads, without either depending on the other.

#include <cstdint>
#include <vector>

namespace sextant {

struct GrayImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;

  std::uint8_t at(int u, int v) const { return pixels[static_cast<std::size_t>(v) * width + u]; }
};

}  // namespace sextant
