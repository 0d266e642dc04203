#include "recog/pipeline/recognition_paths.hpp"

namespace sh {

Status RecognitionPaths::Allocate(bool printed, bool one_camera) {
  if (printed && texture_ == nullptr) {
    texture_ = MakeZeroed<texture::TextureRecognizer>();
    texture_result_ = MakeZeroed<texture::TextureResult>();
    if (texture_ == nullptr || texture_result_ == nullptr) {
      return Status::Error(StatusCode::kUnavailable, "cannot allocate the texture path's %zu bytes",
                           sizeof(texture::TextureRecognizer) + sizeof(texture::TextureResult));
    }
  }
  if (one_camera && mono_ == nullptr) {
    mono_ = MakeZeroed<MonoPipeline>();
    mono_result_ = MakeZeroed<MonoResult>();
    if (mono_ == nullptr || mono_result_ == nullptr) {
      return Status::Error(StatusCode::kUnavailable,
                           "cannot allocate the one-camera fallback's %zu bytes",
                           sizeof(MonoPipeline) + sizeof(MonoResult));
    }
  }
  return Status::Ok();
}

}  // namespace sh
