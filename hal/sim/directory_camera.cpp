#include "hal/sim/directory_camera.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <new>
#include <utility>

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "hal/sim/image_files.hpp"
#include "recog/image/binning.hpp"
#include "tables/input_file.hpp"

namespace sh::hal {
namespace {

bool IsDirectory(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

// The file name, with its folder when the name alone ("left.png" of a scene folder) does not
// say which pair it is.
const char* BaseName(const std::string& path) {
  const size_t slash = path.rfind('/');
  const char* name = path.c_str() + (slash == std::string::npos ? 0 : slash + 1);
  const bool generic = !std::strncmp(name, "left.", 5) || !std::strncmp(name, "right.", 6);
  if (generic && slash != std::string::npos && slash > 0) {
    const size_t parent = path.rfind('/', slash - 1);
    return path.c_str() + (parent == std::string::npos ? 0 : parent + 1);
  }
  return name;
}

const char* SideName(int side) { return side == 0 ? "left" : "right"; }

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

// Names of the image files (.png, .pgm) in `dir`; errors name the directory.
Status ListFiles(const std::string& dir, std::vector<std::string>* names) {
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) {
    const int err = errno;
    return Status::Error(err == ENOENT ? StatusCode::kNotFound : StatusCode::kUnavailable,
                         "cannot open recording directory %s: %s", dir.c_str(), std::strerror(err));
  }
  while (const dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name[0] == '.' || !(EndsWith(name, ".png") || EndsWith(name, ".pgm"))) continue;
    names->push_back(name);
  }
  closedir(d);
  return Status::Ok();
}

std::string JoinPath(const std::string& dir, const std::string& name) {
  std::string path = dir;
  path.append("/").append(name);
  return path;
}

// The image file `side` ("left", "right") of a scene folder: side.png or side.pgm, "" if none.
std::string SceneImage(const std::string& folder, const char* side) {
  for (const char* ext : {".png", ".pgm"}) {
    std::string path = folder;
    path.append("/").append(side).append(ext);
    struct stat st {};
    if (stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode)) return path;
  }
  return "";
}

// Folders of `dir` (not hidden).
Status ListFolders(const std::string& dir, std::vector<std::string>* names) {
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) {
    return Status::Error(StatusCode::kUnavailable, "cannot open recording directory %s: %s",
                         dir.c_str(), std::strerror(errno));
  }
  while (const dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    std::string path = dir;
    path.append("/").append(name);
    if (name[0] != '.' && IsDirectory(path)) names->push_back(name);
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
  *key = name.substr(start, name.size() - start - 4);  // without ".png" / ".pgm"
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
    SH_RETURN_IF_ERROR(ListFiles(left_dir, &names));
    for (const std::string& n : names) left_by_key[n] = JoinPath(left_dir, n);
    names.clear();
    SH_RETURN_IF_ERROR(ListFiles(right_dir, &names));
    for (const std::string& n : names) right_by_key[n] = JoinPath(right_dir, n);
  } else {
    std::vector<std::string> names;
    SH_RETURN_IF_ERROR(ListFiles(directory_, &names));
    for (const std::string& n : names) {
      std::string key;
      if (StripPrefix(n, "left", &key)) {
        left_by_key[key] = directory_ + "/" + n;
      } else if (StripPrefix(n, "right", &key)) {
        right_by_key[key] = directory_ + "/" + n;
      }
    }
    if (left_by_key.empty() && right_by_key.empty()) {
      // Recorded-scenes layout: one folder per pair with left.png and right.png (and whatever
      // else, truth.json, result.json, which playback ignores).
      std::vector<std::string> folders;
      SH_RETURN_IF_ERROR(ListFolders(directory_, &folders));
      for (const std::string& f : folders) {
        std::string folder = directory_;
        folder.append("/").append(f);
        const std::string left = SceneImage(folder, "left");
        const std::string right = SceneImage(folder, "right");
        if (!left.empty()) left_by_key[f] = left;
        if (!right.empty()) right_by_key[f] = right;
      }
    }
  }
  for (const auto& [key, path] : left_by_key) {
    if (right_by_key.count(key) == 0) {
      return Status::Error(StatusCode::kInvalidArgument, "recording: %s has no right partner",
                           BaseName(path));
    }
  }
  for (const auto& [key, path] : right_by_key) {
    const auto left = left_by_key.find(key);
    if (left == left_by_key.end()) {
      return Status::Error(StatusCode::kInvalidArgument, "recording: %s has no left partner",
                           BaseName(path));
    }
    pairs_.push_back(PathPair{key, left->second, path});
  }
  if (pairs_.empty()) {
    return Status::Error(StatusCode::kNotFound,
                         "no left/right image pairs in %s (left_N.png + right_N.png, left/ + "
                         "right/ folders, or one folder per pair with left.png + right.png; .png "
                         "or .pgm)",
                         directory_.c_str());
  }
  std::sort(pairs_.begin(), pairs_.end(),
            [](const PathPair& a, const PathPair& b) { return NaturalLess(a.key, b.key); });
  return Status::Ok();
}

Status DirectoryFrameSource::AllocateFileBuffer() {
  size_t largest = 1;
  for (const PathPair& p : pairs_) {
    for (const std::string* path : {&p.left, &p.right}) {
      struct stat st {};
      if (stat(path->c_str(), &st) != 0) {
        return Status::Error(StatusCode::kNotFound, "recording: cannot stat %s: %s",
                             BaseName(*path), std::strerror(errno));
      }
      if (!S_ISREG(st.st_mode)) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "recording: %s is %s, not a regular file", BaseName(*path),
                             FileTypeName(unsigned(st.st_mode)));
      }
      const size_t bytes = static_cast<size_t>(st.st_size);
      if (bytes > kMaxImageFileBytes) {
        return Status::Error(StatusCode::kOutOfRange, "recording: %s has %zu bytes, limit %zu",
                             BaseName(*path), bytes, kMaxImageFileBytes);
      }
      largest = std::max(largest, bytes);
    }
  }
  file_buffer_.reset(new (std::nothrow) uint8_t[largest]);
  file_capacity_ = largest;
  if (!file_buffer_) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "recording: cannot allocate %zu bytes of file buffer", largest);
  }
  return Status::Ok();
}

Status DirectoryFrameSource::AllocateDecodeBuffers(int width, int height) {
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (pixels == decode_capacity_ && decode_[0] && decode_[1]) return Status::Ok();
  decode_capacity_ = 0;
  for (auto& d : decode_) d.reset(new (std::nothrow) uint8_t[pixels]);
  if (!decode_[0] || !decode_[1]) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "recording: cannot allocate %zu bytes of decode buffers", 2 * pixels);
  }
  decode_capacity_ = pixels;
  return Status::Ok();
}

Status DirectoryFrameSource::AllocateDecodeBuffersFor(const PathPair& pair) {
  // Both headers: a right image larger than the left one is then decoded and refused as a
  // left/right mismatch, not as a frame larger than the buffers.
  ImageInfo sizes[2];
  for (int side = 0; side < 2; ++side) {
    const std::string& path = side == 0 ? pair.left : pair.right;
    size_t size = 0;
    SH_RETURN_IF_ERROR(ReadFile(side, path, &size));
    const Result<ImageInfo> header = ImageFileSize(file_buffer_.get(), size);
    if (!header.ok()) return header.status().WithContext("%s %s", SideName(side), BaseName(path));
    sizes[side] = *header;
  }
  const ImageInfo& larger = static_cast<size_t>(sizes[0].width) * sizes[0].height >=
                                    static_cast<size_t>(sizes[1].width) * sizes[1].height
                                ? sizes[0]
                                : sizes[1];
  width_ = larger.width;  // until the pair decodes: named by a refusal of a larger frame
  height_ = larger.height;
  return AllocateDecodeBuffers(larger.width, larger.height);
}

Status DirectoryFrameSource::ReadFile(int side, const std::string& path, size_t* size_out) {
  // The buffer was sized at Start(): a file that grew since is refused by ReadAll.
  char what[16];
  std::snprintf(what, sizeof(what), "%s image", SideName(side));
  InputFile file;
  SH_RETURN_IF_ERROR(file.Open(path.c_str(), what, kMaxImageFileBytes));
  return file.ReadAll(reinterpret_cast<char*>(file_buffer_.get()), file_capacity_, size_out);
}

Status DirectoryFrameSource::Decode(int side, const std::string& path, uint8_t* pixels,
                                    Decoded* out) {
  size_t size = 0;
  SH_RETURN_IF_ERROR(ReadFile(side, path, &size));
  // The decode buffers hold the recording's first pair: a larger frame is refused by name.
  const Result<ImageInfo> header = ImageFileSize(file_buffer_.get(), size);
  if (header.ok() &&
      static_cast<size_t>(header->width) * static_cast<size_t>(header->height) > decode_capacity_) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s %s is %dx%d, larger than the recording's first pair (%dx%d), for "
                         "which the playback buffers are sized",
                         SideName(side), BaseName(path), header->width, header->height, width_,
                         height_);
  }
  const Result<ImageInfo> info =
      DecodeImage(file_buffer_.get(), size, PixelFormat::kGray8, pixels, decode_capacity_);
  if (!info.ok()) return info.status().WithContext("%s %s", SideName(side), BaseName(path));
  out->width = info->width;
  out->height = info->height;
  return Status::Ok();
}

Status DirectoryFrameSource::Open(int* width, int* height) {
  SH_RETURN_IF_ERROR(Scan());
  SH_RETURN_IF_ERROR(AllocateFileBuffer());
  // The first pair that decodes sets the size, and the decode buffers are sized for it (read
  // from both files' headers, the larger); a broken first file then shows up as a per-frame error
  // at playback instead of refusing the whole recording.
  Status first_error;
  for (const PathPair& p : pairs_) {
    Decoded l;
    Decoded r;
    Status s = AllocateDecodeBuffersFor(p);
    if (s.code() == StatusCode::kResourceExhausted) return s;
    if (s.ok()) s = Decode(0, p.left, decode_[0].get(), &l);
    if (s.ok()) s = Decode(1, p.right, decode_[1].get(), &r);
    if (s.ok() && (l.width != r.width || l.height != r.height)) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "recording: %s is %dx%d but %s is %dx%d; left and right must match",
                           BaseName(p.left), l.width, l.height, BaseName(p.right), r.width,
                           r.height);
    }
    if (s.ok()) {
      width_ = l.width;
      height_ = l.height;
      const Result<int> bin = BinFactorFor(l.width, l.height);
      if (!bin.ok()) return bin.status().WithContext("recording %s", BaseName(p.left));
      bin_ = *bin;
      *width = frame_width_ = BinnedSize(l.width, bin_);
      *height = frame_height_ = BinnedSize(l.height, bin_);
      // Playback decodes into the camera's frames; a binned recording keeps the decode buffers
      // for its full-size images, else they served this check only.
      if (bin_ == 1) {
        for (auto& d : decode_) d.reset();
      }
      return Status::Ok();
    }
    if (first_error.ok()) first_error = s;
  }
  return first_error.WithContext("recording has no readable pair; first problem");
}

Status DirectoryFrameSource::Render(uint64_t frame_index, GrayView left, GrayView right) {
  if (pairs_.empty() || !file_buffer_) {
    return Status::Error(StatusCode::kFailedPrecondition, "recording not opened");
  }
  if (!loop_ && frame_index >= pairs_.size()) {
    return Status::Error(StatusCode::kOutOfRange, "end of recording after %zu pairs",
                         pairs_.size());
  }
  if (left.width != frame_width_ || left.height != frame_height_ || left.stride < frame_width_ ||
      right.width != frame_width_ || right.height != frame_height_ || right.stride < frame_width_) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "recording frames are %dx%d, the camera's %dx%d (stride %d) and %dx%d "
                         "(stride %d)",
                         frame_width_, frame_height_, left.width, left.height, left.stride,
                         right.width, right.height, right.stride);
  }
  // Decoded straight into the camera's frames, rows packed: a frame of width_ x height_ pixels
  // fits in a view of that size whatever its stride (stride >= width). A binned recording is
  // decoded into its full-size buffers and binned into the frames.
  const PathPair& p = pairs_[frame_index % pairs_.size()];
  const GrayView views[2] = {left, right};
  Decoded d[2];
  for (int side = 0; side < 2; ++side) {
    uint8_t* target = bin_ == 1 ? views[side].data : decode_[side].get();
    SH_RETURN_IF_ERROR(Decode(side, side == 0 ? p.left : p.right, target, &d[side]));
  }
  if (d[0].width != d[1].width || d[0].height != d[1].height) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s is %dx%d but %s is %dx%d; left and right must match", BaseName(p.left),
                         d[0].width, d[0].height, BaseName(p.right), d[1].width, d[1].height);
  }
  if (d[0].width != width_ || d[0].height != height_) {
    return Status::Error(StatusCode::kInvalidArgument, "%s is %dx%d, expected %dx%d",
                         BaseName(p.left), d[0].width, d[0].height, width_, height_);
  }
  if (bin_ > 1) {
    for (int side = 0; side < 2; ++side) {
      const ConstGrayView full{decode_[side].get(), width_, height_, width_};
      SH_RETURN_IF_ERROR(BinGray(full, bin_, views[side]));
    }
    return Status::Ok();
  }
  // Packed rows to the view's stride, the last row first (each moves to a later or the same
  // place, so no row is overwritten before it has moved).
  for (const GrayView& v : views) {
    if (v.stride == width_) continue;
    for (int y = height_ - 1; y > 0; --y) {
      std::memmove(v.row(y), v.data + static_cast<size_t>(y) * width_, static_cast<size_t>(width_));
    }
  }
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
