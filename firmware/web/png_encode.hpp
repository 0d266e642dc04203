// 8-bit grey images as PNG in memory (libpng), for the live view. Fast compression: the page
// refreshes a few times a second and the link is local.
#pragma once

#include <cstdint>
#include <vector>

#include "recog/base/status.hpp"

namespace sh::fw::web {

// `pixels`: width x height, packed rows. Replaces *png.
Status EncodeGrayPng(const uint8_t* pixels, int width, int height, std::vector<uint8_t>* png);

}  // namespace sh::fw::web
