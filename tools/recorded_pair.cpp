#include "tools/recorded_pair.hpp"

#include <unistd.h>

namespace sh::tools {
namespace {

bool Readable(const std::string& path) { return access(path.c_str(), R_OK) == 0; }

// DIR/side.png or DIR/side.pgm, "" if neither.
std::string Image(const std::string& dir, const char* side) {
  for (const char* ext : {".png", ".pgm"}) {
    std::string path = dir;
    path.append("/").append(side).append(ext);
    if (Readable(path)) return path;
  }
  return "";
}

}  // namespace

Status FindRecordedPair(const char* scene_dir, RecordedPair* out) {
  std::string dir = scene_dir;
  while (dir.size() > 1 && dir.back() == '/') dir.pop_back();
  out->left = Image(dir, "left");
  out->right = Image(dir, "right");
  if (out->left.empty() && out->right.empty()) {
    return Status::Error(StatusCode::kNotFound, "%s has neither left nor right .png (or .pgm)",
                         dir.c_str());
  }
  const std::string parent = dir + "/..";
  // Missing: "" (the caller refuses it unless --calib gives the calibration).
  out->calib = Readable(parent + "/calib.yaml") ? parent + "/calib.yaml" : "";
  out->table = Readable(parent + "/table.yaml") ? parent + "/table.yaml" : "";
  return Status::Ok();
}

}  // namespace sh::tools
