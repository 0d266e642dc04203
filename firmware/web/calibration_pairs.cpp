#include "firmware/web/calibration_pairs.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/web/png_encode.hpp"
#include "firmware/web/recordings.hpp"

namespace sh::fw::web {
namespace {

constexpr char kDoneFile[] = "capture.json";

Status WriteFile(const std::string& path, const void* data, size_t bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    return Status::Error(StatusCode::kUnavailable, "cannot write %s: %s", path.c_str(),
                         std::strerror(errno));
  }
  const bool written = std::fwrite(data, 1, bytes, f) == bytes;
  const bool closed = std::fclose(f) == 0;
  if (!written || !closed) {
    return Status::Error(StatusCode::kUnavailable, "cannot write %s: %s", path.c_str(),
                         std::strerror(errno));
  }
  return Status::Ok();
}

Status MakeDir(const std::string& path) {
  if (mkdir(path.c_str(), 0755) != 0 && errno != EEXIST) {
    return Status::Error(StatusCode::kUnavailable, "cannot create %s: %s", path.c_str(),
                         std::strerror(errno));
  }
  return Status::Ok();
}

// left.png, right.png and capture.json into `dir`.
Status WritePair(const std::string& dir, const PairCapture& capture) {
  std::vector<uint8_t> png;
  for (int side = 0; side < 2; ++side) {
    SH_RETURN_IF_ERROR(
        EncodeGrayPng(capture.pixels(side), capture.width(side), capture.height(side), &png));
    SH_RETURN_IF_ERROR(
        WriteFile(dir + (side == 0 ? "/left.png" : "/right.png"), png.data(), png.size()));
  }
  char json[128];
  const int n =
      std::snprintf(json, sizeof(json), "{\"left\": [%d, %d], \"right\": [%d, %d]}\n",
                    capture.width(0), capture.height(0), capture.width(1), capture.height(1));
  return WriteFile(dir + "/" + kDoneFile, json, static_cast<size_t>(n));
}

}  // namespace

std::string CalibrationDir(const char* record_dir) {
  return std::string(record_dir) + "/calibration";
}

std::vector<std::string> ListCalibrationPairs(const char* record_dir) {
  return ListPairs(CalibrationDir(record_dir).c_str(), kMaxCalibrationPairs, kDoneFile);
}

Result<SavedPair> SaveCalibrationPair(const char* record_dir, const PairCapture& capture) {
  const std::string dir = CalibrationDir(record_dir);
  SH_RETURN_IF_ERROR(MakeDir(record_dir));
  SH_RETURN_IF_ERROR(MakeDir(dir));
  const std::vector<std::string> pairs = ListCalibrationPairs(record_dir);
  if (pairs.size() >= kMaxCalibrationPairs) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "%zu calibration pairs already (download them and remove %s)",
                         pairs.size(), dir.c_str());
  }
  char name[16];
  const long next = pairs.empty() ? 1 : std::strtol(pairs.back().c_str(), nullptr, 10) + 1;
  std::snprintf(name, sizeof(name), "%08ld", next);
  // Under a name no listing takes, then renamed: a listed pair is whole.
  const std::string part = dir + "/." + name + ".part";
  SH_RETURN_IF_ERROR(MakeDir(part));
  Status s = WritePair(part, capture);
  if (s.ok() && std::rename(part.c_str(), (dir + "/" + name).c_str()) != 0) {
    s = Status::Error(StatusCode::kUnavailable, "cannot rename %s: %s", part.c_str(),
                      std::strerror(errno));
  }
  if (!s.ok()) {
    for (const char* f : {"/left.png", "/right.png", "/capture.json"}) {
      (void)unlink((part + f).c_str());
    }
    (void)rmdir(part.c_str());
    return s;
  }
  return SavedPair{name, pairs.size() + 1};
}

}  // namespace sh::fw::web
