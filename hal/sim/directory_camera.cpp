#include "hal/sim/directory_camera.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>
#include <utility>

#include <dirent.h>
#include <sys/stat.h>

#include "hal/sim/directory_camera_pgm.hpp"

namespace sh::hal {
namespace {

bool IsDirectory(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

bool EndsWith(const std::string& s, const char* suffix) {
  const size_t n = std::strlen(suffix);
  return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
}

// Natural order: runs of digits compare by value, so frame_2 plays before frame_10.
bool NaturalLess(const std::string& a, const std::string& b) {
  size_t i = 0;
  size_t j = 0;
  while (i < a.size() && j < b.size()) {
    const bool da = a[i] >= '0' && a[i] <= '9';
    const bool db = b[j] >= '0' && b[j] <= '9';
    if (da && db) {
      size_t ie = i;
      size_t je = j;
      while (ie < a.size() && a[ie] >= '0' && a[ie] <= '9') ++ie;
      while (je < b.size() && b[je] >= '0' && b[je] <= '9') ++je;
      // Compare values without overflow: strip leading zeros, then length, then digits.
      size_t is = i;
      size_t js = j;
      while (is + 1 < ie && a[is] == '0') ++is;
      while (js + 1 < je && b[js] == '0') ++js;
      if (ie - is != je - js) return ie - is < je - js;
      const int c = a.compare(is, ie - is, b, js, je - js);
      if (c != 0) return c < 0;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

// Names of regular entries of `dir` ending in `extension`; errors name the directory.
Status ListFiles(const std::string& dir, const char* extension, std::vector<std::string>* names) {
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) {
    const int err = errno;
    return Status::Error(err == ENOENT ? StatusCode::kNotFound : StatusCode::kUnavailable,
                         "cannot open recording directory %s: %s", dir.c_str(), std::strerror(err));
  }
  while (const dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name[0] == '.' || !EndsWith(name, extension)) continue;
    names->push_back(name);
  }
  closedir(d);
  return Status::Ok();
}

// "left_0001.pgm" -> "0001" for prefix "left"; accepts "left0001", "left_0001", "left-0001".
bool StripPrefix(const std::string& name, const char* prefix, std::string* key) {
  const size_t n = std::strlen(prefix);
  if (name.compare(0, n, prefix) != 0) return false;
  size_t start = n;
  if (start < name.size() && (name[start] == '_' || name[start] == '-')) ++start;
  *key = name.substr(start, name.size() - start - 4);  // without ".pgm"
  return !key->empty() || name.size() > n + 4;
}

}  // namespace

DirectoryFrameSource::DirectoryFrameSource(std::string directory, bool loop)
    : directory_(std::move(directory)), loop_(loop) {}

Status DirectoryFrameSource::Scan() {
  pairs_.clear();
  if (!IsDirectory(directory_)) {
    return Status::Error(StatusCode::kNotFound, "recording directory %s does not exist",
                         directory_.c_str());
  }
  std::map<std::string, std::string> left_by_key;
  std::map<std::string, std::string> right_by_key;
  const std::string left_dir = directory_ + "/left";
  const std::string right_dir = directory_ + "/right";
  if (IsDirectory(left_dir) && IsDirectory(right_dir)) {
    std::vector<std::string> names;
    SH_RETURN_IF_ERROR(ListFiles(left_dir, ".pgm", &names));
    for (const std::string& n : names) left_by_key[n] = left_dir + "/" + n;
    names.clear();
    SH_RETURN_IF_ERROR(ListFiles(right_dir, ".pgm", &names));
    for (const std::string& n : names) right_by_key[n] = right_dir + "/" + n;
  } else {
    std::vector<std::string> names;
    SH_RETURN_IF_ERROR(ListFiles(directory_, ".pgm", &names));
    for (const std::string& n : names) {
      std::string key;
      if (StripPrefix(n, "left", &key)) {
        left_by_key[key] = directory_ + "/" + n;
      } else if (StripPrefix(n, "right", &key)) {
        right_by_key[key] = directory_ + "/" + n;
      }
    }
  }
  for (const auto& [key, path] : left_by_key) {
    if (right_by_key.count(key) == 0) {
      return Status::Error(StatusCode::kInvalidArgument, "recording: %s has no right partner",
                           PathBaseName(path.c_str()));
    }
  }
  for (const auto& [key, path] : right_by_key) {
    const auto left = left_by_key.find(key);
    if (left == left_by_key.end()) {
      return Status::Error(StatusCode::kInvalidArgument, "recording: %s has no left partner",
                           PathBaseName(path.c_str()));
    }
    pairs_.push_back(PathPair{key, left->second, path});
  }
  if (pairs_.empty()) {
    return Status::Error(StatusCode::kNotFound,
                         "no left/right .pgm pairs in %s (left_N.pgm + right_N.pgm or left/ + "
                         "right/ folders)",
                         directory_.c_str());
  }
  std::sort(pairs_.begin(), pairs_.end(),
            [](const PathPair& a, const PathPair& b) { return NaturalLess(a.key, b.key); });
  return Status::Ok();
}

Status DirectoryFrameSource::Open(int* width, int* height) {
  SH_RETURN_IF_ERROR(Scan());
  // The first pair whose headers both read sets the size; a broken first file then shows up as a
  // per-frame error at playback instead of refusing the whole recording.
  Status first_error;
  for (const PathPair& p : pairs_) {
    PgmHeader l;
    PgmHeader r;
    Status s = ReadPgmHeader(p.left.c_str(), &l);
    if (s.ok()) s = ReadPgmHeader(p.right.c_str(), &r);
    if (s.ok() && (l.width != r.width || l.height != r.height)) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "recording: %s is %dx%d but %s is %dx%d; left and right must match",
                           PathBaseName(p.left.c_str()), l.width, l.height,
                           PathBaseName(p.right.c_str()), r.width, r.height);
    }
    if (s.ok()) {
      width_ = *width = l.width;
      height_ = *height = l.height;
      return Status::Ok();
    }
    if (first_error.ok()) first_error = s;
  }
  return Status::Error(first_error.code(), "recording has no readable pair; first problem: %s",
                       first_error.message());
}

Status DirectoryFrameSource::Render(uint64_t frame_index, GrayView left, GrayView right) {
  if (pairs_.empty()) {
    return Status::Error(StatusCode::kFailedPrecondition, "recording not opened");
  }
  if (!loop_ && frame_index >= pairs_.size()) {
    return Status::Error(StatusCode::kOutOfRange, "end of recording after %zu pairs",
                         pairs_.size());
  }
  const PathPair& p = pairs_[frame_index % pairs_.size()];
  PgmHeader l;
  PgmHeader r;
  // Errors are prefixed with the side: in the left/ right/ layout both files share a name.
  Status s = ReadPgmHeader(p.left.c_str(), &l);
  if (!s.ok()) return Status::Error(s.code(), "left %s", s.message());
  s = ReadPgmHeader(p.right.c_str(), &r);
  if (!s.ok()) return Status::Error(s.code(), "right %s", s.message());
  if (l.width != r.width || l.height != r.height) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s is %dx%d but %s is %dx%d; left and right must match",
                         PathBaseName(p.left.c_str()), l.width, l.height,
                         PathBaseName(p.right.c_str()), r.width, r.height);
  }
  s = ReadPgmInto(p.left.c_str(), left);
  if (!s.ok()) return Status::Error(s.code(), "left %s", s.message());
  s = ReadPgmInto(p.right.c_str(), right);
  if (!s.ok()) return Status::Error(s.code(), "right %s", s.message());
  return Status::Ok();
}

SimCameraConfig DirectoryCamera::MakeSimConfig(const DirectoryCameraConfig& config) {
  SimCameraConfig sim;
  sim.frame_period_ns = config.frame_period_ns;
  sim.first_timestamp_ns = config.first_timestamp_ns;
  sim.pairing = config.pairing;
  return sim;
}

DirectoryCamera::DirectoryCamera(const DirectoryCameraConfig& config)
    : source_(config.directory, config.loop), camera_(&source_, MakeSimConfig(config)) {}

}  // namespace sh::hal
