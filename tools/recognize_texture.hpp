// `stereohash recognize` with a feature database (printed models): the texture path on one
// stereo pair, printed like the polyhedral results, as JSON in the same form, and as the same
// side-by-side overlay.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/image/image.hpp"
#include "recog/texture/texture_recognizer.hpp"
#include "recog/verify/view_camera.hpp"
#include "tables/feature_db_view.hpp"
#include "tables/table_file.hpp"

namespace sh::tools {

struct TextureRun {
  const char* json_path = nullptr;
  const char* overlay_path = nullptr;
  int threads = 0;  // 0: all cores
};

// Recognises the printed models of `db` in the pair and reports them; returns the exit code.
int RecognizePrinted(const StereoCalibration& calib, const FeatureDbView& db, ConstGrayView left,
                     ConstGrayView right, const TextureRun& run);

// The objects found, a line each, on stdout.
void PrintTextureObjects(const FeatureDbView& db, const texture::TextureResult& result);

// {"frame": "camera", "objects": [{"model", "R", "t", "verify": [left, right], "faces",
// "feature_matches", "stereo_points"}], "texture": {...}, "time_ms": {...}, "threads": N}
std::string TextureResultJson(const FeatureDbView& db, const texture::TextureResult& result,
                              int threads);

}  // namespace sh::tools
