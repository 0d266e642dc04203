#include "tools/recorded_pair.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

#include "tables/input_file.hpp"
#include "tables/model_set.hpp"
#include "tables/table_file.hpp"

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

// A settings.conf is a firmware configuration file, bounded as one (kMaxConfigFileBytes).
constexpr size_t kMaxSettingsBytes = size_t{64} * 1024;

// The `key = value` lines of a recording's settings.conf: the same syntax, # comments and spaces
// as the firmware's configuration file; a later line wins. Read as every input is (a regular
// file within its bound, never blocking).
Status ReadRecordedSettings(const std::string& path, std::map<std::string, std::string>* out) {
  std::string text;
  SH_RETURN_IF_ERROR(ReadInputFile(path, "recording settings", kMaxSettingsBytes, &text));
  const auto trim = [](const std::string& s) {
    const size_t a = s.find_first_not_of(" \t\r");
    const size_t b = s.find_last_not_of(" \t\r");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
  };
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    line = line.substr(0, line.find('#'));
    const size_t eq = line.find('=');
    if (eq == std::string::npos) continue;
    (*out)[trim(line.substr(0, eq))] = trim(line.substr(eq + 1));
  }
  return Status::Ok();
}

// Three finite numbers separated by spaces or commas, as the firmware's configuration reads
// volume_min_mm (its parser is the firmware's own, which the host tools do not link).
bool ParseVector3(const std::string& text, float out[3]) {
  const char* p = text.c_str();
  for (int k = 0; k < 3; ++k) {
    while (*p == ' ' || *p == '\t' || *p == ',') ++p;
    char* end = nullptr;
    const float v = std::strtof(p, &end);
    if (end == p || !std::isfinite(v)) return false;
    out[k] = v;
    p = end;
  }
  while (*p == ' ' || *p == '\t') ++p;
  return *p == '\0';
}

Status ReadVolume(const std::string& path, const std::map<std::string, std::string>& settings,
                  RecordedVolume* out) {
  const auto min = settings.find("volume_min_mm"), max = settings.find("volume_max_mm");
  if (min == settings.end() || max == settings.end()) return Status::Ok();
  if (!ParseVector3(min->second, out->min_mm) || !ParseVector3(max->second, out->max_mm)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s: volume_min_mm and volume_max_mm: expected three numbers each",
                         path.c_str());
  }
  for (int k = 0; k < 3; ++k) {
    if (!(out->min_mm[k] < out->max_mm[k])) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s: volume_min_mm must be below volume_max_mm on every axis",
                           path.c_str());
    }
  }
  const auto frame = settings.find("volume_frame");
  const std::string frame_name = frame == settings.end() ? "camera" : frame->second;
  if (frame_name != "camera" && frame_name != "table") {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s: volume_frame %s: expected camera or table", path.c_str(),
                         frame_name.c_str());
  }
  out->in_table_frame = frame_name == "table";
  out->present = true;
  return Status::Ok();
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
  out->rig_table = Readable(parent + "/rig_table.yaml") ? parent + "/rig_table.yaml" : "";
  const std::string settings_path = parent + "/settings.conf";
  std::map<std::string, std::string> settings;
  if (access(settings_path.c_str(), F_OK) == 0) {
    SH_RETURN_IF_ERROR(ReadRecordedSettings(settings_path, &settings));
  }
  const auto found = settings.find("background");
  const std::string background = found == settings.end() ? "" : found->second;
  if (!background.empty() && background != "auto" && background != "dark" &&
      background != "light") {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s: background %s: expected auto, dark or light", settings_path.c_str(),
                         background.c_str());
  }
  out->background = background == "auto" ? "" : background;
  const auto tables = settings.find("tables");
  if (tables != settings.end() && tables->second != "builtin") out->tables = tables->second;
  const auto crc32 = settings.find("tables_crc32");
  if (crc32 != settings.end() && !ParseBlobCrc32(crc32->second.c_str(), &out->tables_crc32)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s: tables_crc32 %s: expected 0 or a CRC-32 of up to 8 hex digits",
                         settings_path.c_str(), crc32->second.c_str());
  }
  return ReadVolume(settings_path, settings, &out->volume);
}

Status CheckRecordedTables(const RecordedPair& recorded, const char* tables_path) {
  if (recorded.tables_crc32 == 0) return Status::Ok();
  uint32_t crc32 = BlobHeaderCrc32(DefaultTableBlob(), DefaultTableBlobSize());
  if (tables_path != nullptr) {
    SH_ASSIGN_OR_RETURN(crc32, FileBlobCrc32(tables_path));
  }
  if (crc32 == recorded.tables_crc32) return Status::Ok();
  return Status::Error(StatusCode::kFailedPrecondition,
                       "the recording's model set %s carries CRC-32 %08x, not the %08x it was "
                       "recognised with (settings.conf tables_crc32): rebuilt or replaced since; "
                       "give --tables to replay with another set",
                       tables_path != nullptr ? tables_path : "(built-in)", crc32,
                       recorded.tables_crc32);
}

}  // namespace sh::tools
