#include "firmware/web/png_encode.hpp"

#include <png.h>

#include <csetjmp>

namespace sh::fw::web {
namespace {

void Append(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::vector<uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + length);
}

void Flush(png_structp) {}

}  // namespace

Status EncodeGrayPng(const uint8_t* pixels, int width, int height, std::vector<uint8_t>* out) {
  if (pixels == nullptr || width <= 0 || height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "no image to encode");
  }
  out->clear();
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (png == nullptr) return Status::Error(StatusCode::kUnavailable, "libpng: out of memory");
  png_infop info = png_create_info_struct(png);
  // libpng reports its errors by longjmp: nothing with a destructor lives in this frame past
  // this point, the rows come straight from `pixels`.
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return Status::Error(StatusCode::kInternal, "libpng could not encode the image");
  }
  png_set_write_fn(png, out, &Append, &Flush);
  png_set_compression_level(png, 1);
  png_set_filter(png, 0, PNG_FILTER_SUB);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) {
    png_write_row(png, const_cast<png_bytep>(pixels + static_cast<size_t>(y) * width));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return Status::Ok();
}

}  // namespace sh::fw::web
