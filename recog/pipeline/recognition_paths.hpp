// The storage of the recognition paths behind the facade (object_recognizer.hpp): the stereo
// pipeline always, the printed cartons' texture path and the one-camera fallback when the
// installation needs them. Their buffers are large (docs/memory.md), so they are allocated once at
// start-up, zeroed (no page resident until used), and never again.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/base/zeroed.hpp"
#include "recog/mono/mono_pipeline.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/texture/texture_recognizer.hpp"

namespace sh {

// Cartons the texture path reports per frame.
inline constexpr size_t kMaxRecognitionCartons = texture::kMaxTextureObjects;

// The paths the facade runs, owned elsewhere; null: the path is not there.
struct RecognitionPathSet {
  Pipeline* stereo = nullptr;  // required
  texture::TextureRecognizer* texture = nullptr;
  texture::TextureResult* texture_result = nullptr;
  MonoPipeline* mono = nullptr;
  MonoResult* mono_result = nullptr;
};

// Owns the paths: the stereo pipeline in the object itself (11 MiB; keep it in static storage),
// the others allocated by Allocate().
class RecognitionPaths {
 public:
  // Allocates the texture path (about 63 MiB, `printed`) and the monocular fallback (1.0 MiB,
  // `one_camera`), zeroed; once, at start-up. kUnavailable names the path that did not fit.
  Status Allocate(bool printed, bool one_camera);
  RecognitionPathSet set() {
    return {&stereo_, texture_.get(), texture_result_.get(), mono_.get(), mono_result_.get()};
  }

 private:
  Pipeline stereo_;
  ZeroedPtr<texture::TextureRecognizer> texture_;
  ZeroedPtr<texture::TextureResult> texture_result_;
  ZeroedPtr<MonoPipeline> mono_;
  ZeroedPtr<MonoResult> mono_result_;
};

}  // namespace sh
