#include "tools/recorded_pair.hpp"

#include <unistd.h>

#include <fstream>

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

// The `background` value of a recording's settings.conf ("" without one): the same
// `key = value` lines, # comments and spaces as the firmware's configuration file.
std::string RecordedBackground(const std::string& path) {
  std::ifstream in(path);
  std::string line, value;
  while (std::getline(in, line)) {
    line = line.substr(0, line.find('#'));
    const size_t eq = line.find('=');
    if (eq == std::string::npos) continue;
    const auto trim = [](const std::string& s) {
      const size_t a = s.find_first_not_of(" \t\r");
      const size_t b = s.find_last_not_of(" \t\r");
      return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
    };
    if (trim(line.substr(0, eq)) == "background") value = trim(line.substr(eq + 1));
  }
  return value;
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
  const std::string settings = parent + "/settings.conf";
  const std::string background = Readable(settings) ? RecordedBackground(settings) : "";
  if (!background.empty() && background != "auto" && background != "dark" &&
      background != "light") {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s: background %s: expected auto, dark or light", settings.c_str(),
                         background.c_str());
  }
  out->background = background == "auto" ? "" : background;
  return Status::Ok();
}

}  // namespace sh::tools
