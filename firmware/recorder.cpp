#include "firmware/recorder.hpp"

#include <dirent.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <new>

#include "hal/sim/image_files.hpp"
#include "recog/base/printable.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "recog/camera/table_yaml.hpp"
#include "recog/image/image.hpp"

namespace sh::fw {
namespace {

constexpr size_t kResultJsonBytes =
    size_t{32} * 1024;  // 64 objects at ~250 bytes each, and the header
constexpr size_t kYamlBytes = size_t{16} * 1024;

// mkdir -p for a path of a few components.
bool MakeDirectories(const std::string& path) {
  for (size_t at = 1; at <= path.size(); ++at) {
    if (at != path.size() && path[at] != '/') continue;
    const std::string part = path.substr(0, at);
    if (mkdir(part.c_str(), 0755) != 0 && errno != EEXIST) return false;
  }
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) return false;
  // An existing file or device (/dev/null) where the directory should be: say so by errno.
  if (!S_ISDIR(st.st_mode)) errno = ENOTDIR;
  return S_ISDIR(st.st_mode);
}

// Paths built without the heap: the writer thread allocates nothing either.
constexpr size_t kPathBytes = 512;
struct Path {
  char text[kPathBytes] = {};
  Path(const char* dir, const char* name) { std::snprintf(text, sizeof(text), "%s/%s", dir, name); }
  const char* c_str() const { return text; }
};

// Writes `length` bytes to `path`; errno is kept on failure (fclose reports a full disk).
bool WriteFile(const char* path, const char* data, size_t length) {
  std::FILE* f = std::fopen(path, "wb");
  if (f == nullptr) return false;
  const bool written = std::fwrite(data, 1, length, f) == length;
  const int write_errno = errno;
  const bool closed = std::fclose(f) == 0;
  if (!written) errno = write_errno;
  return written && closed;
}

// Removes a pair folder and the files this recorder writes into it.
bool RemovePair(const char* dir) {
  for (const char* name : {"left.png", "right.png", "left.pgm", "right.pgm", "result.json"}) {
    (void)unlink(Path(dir, name).c_str());
  }
  return rmdir(dir) == 0;
}

bool IsPairName(const char* name, uint64_t* index) {
  if (std::strlen(name) != 8) return false;
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) {
    if (name[i] < '0' || name[i] > '9') return false;
    v = v * 10 + static_cast<uint64_t>(name[i] - '0');
  }
  *index = v;
  return true;
}

}  // namespace

size_t FormatResultJson(const protocol::ResultSet& set, const char* output_frame,
                        const char* background, const char* const* model_names, int model_count,
                        const int64_t timestamp_ns[2], char* out, size_t capacity) {
  size_t used = 0;
  const auto append = [&](const char* fmt, auto... args) {
    if (used >= capacity) return;
    const int n = std::snprintf(out + used, capacity - used, fmt, args...);
    used = n < 0 ? capacity : used + static_cast<size_t>(n);
  };
  append(
      "{\"sequence\": %u, \"request_id\": %u, \"status\": %u, \"processing_time_us\": %u, "
      "\"output_frame\": \"%s\", \"background\": \"%s\", \"timestamps_ns\": [%" PRId64 ", %" PRId64
      "], \"objects\": [",
      set.sequence, set.request_id, static_cast<unsigned>(set.status), set.processing_time_us,
      output_frame, background, timestamp_ns[0], timestamp_ns[1]);
  for (int i = 0; i < set.object_count; ++i) {
    const protocol::ObjectPose& p = set.objects[i];
    const char* raw =
        p.model_id < model_count && model_names != nullptr ? model_names[p.model_id] : "";
    char name[kJsonNameBytes];
    JsonEscaped(raw, kJsonNameBytes, name, sizeof(name));
    append(
        "%s{\"model_id\": %u, \"model\": \"%s\", \"instance\": %u, \"score\": %.4f, "
        "\"t_mm\": [%.4f, %.4f, %.4f], \"q_wxyz\": [%.7f, %.7f, %.7f, %.7f]}",
        i ? ", " : "", p.model_id, name, p.instance, p.score, p.cam_t_model_mm[0],
        p.cam_t_model_mm[1], p.cam_t_model_mm[2], p.cam_q_model[0], p.cam_q_model[1],
        p.cam_q_model[2], p.cam_q_model[3]);
  }
  append("]}\n");
  return used < capacity ? used : 0;
}

Status Recorder::Start(const RecorderConfig& config, const StereoCalibration& calibration,
                       const RigidTransform* left_T_table, RecorderObserver* observer) {
  config_ = config;
  observer_ = observer;
  errno = 0;
  const Status s = StartWriting(calibration, left_T_table);
  // The EMCY detail names the real cause (ENOTDIR under a file, ENOENT under /proc, ...).
  start_error_ = s.ok() ? 0 : errno != 0 ? errno : EIO;
  return s;
}

Status Recorder::StartWriting(const StereoCalibration& calibration,
                              const RigidTransform* left_T_table) {
  if (config_.max_pairs < 1) {
    return Status::Error(StatusCode::kInvalidArgument, "record_max %d: at least 1",
                         config_.max_pairs);
  }
  if (!MakeDirectories(config_.directory)) {
    return Status::Error(StatusCode::kUnavailable, "record_dir %s: %s", config_.directory.c_str(),
                         std::strerror(errno));
  }
  // The set's calibration and table, so that the recording replays and recognises on its own.
  static char yaml[kYamlBytes];
  Result<size_t> n = WriteCalibrationYaml(calibration, yaml, sizeof(yaml));
  if (!n.ok()) return n.status();
  if (!WriteFile(Path(config_.directory.c_str(), "calib.yaml").c_str(), yaml, *n)) {
    return Status::Error(StatusCode::kUnavailable, "record_dir %s: cannot write calib.yaml: %s",
                         config_.directory.c_str(), std::strerror(errno));
  }
  // The settings beside the calibration, in the configuration's own syntax, so that a replay
  // (camera = directory, recognize --scene) reads them as the firmware reads its file.
  if (!WriteFile(Path(config_.directory.c_str(), "settings.conf").c_str(), config_.settings.data(),
                 config_.settings.size())) {
    return Status::Error(StatusCode::kUnavailable, "record_dir %s: cannot write settings.conf: %s",
                         config_.directory.c_str(), std::strerror(errno));
  }
  const struct {
    const RigidTransform* pose;
    const char* file;
  } tables[] = {{left_T_table, "table.yaml"}, {config_.rig_T_table, "rig_table.yaml"}};
  for (const auto& table : tables) {
    if (table.pose == nullptr) continue;
    n = WriteTableYaml(*table.pose, yaml, sizeof(yaml));
    if (n.ok() && !WriteFile(Path(config_.directory.c_str(), table.file).c_str(), yaml, *n)) {
      return Status::Error(StatusCode::kUnavailable, "record_dir %s: cannot write %s: %s",
                           config_.directory.c_str(), table.file, std::strerror(errno));
    }
  }
  // Continue the numbering of an earlier run; keep room for max_pairs - 1 of its pairs.
  uint64_t highest = 0;
  bool any = false;
  if (DIR* d = opendir(config_.directory.c_str())) {
    while (const dirent* e = readdir(d)) {
      uint64_t index = 0;
      struct stat st {};
      const Path path(config_.directory.c_str(), e->d_name);
      if (IsPairName(e->d_name, &index) && stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
        highest = any && highest > index ? highest : index;
        any = true;
      }
    }
    closedir(d);
  }
  next_index_ = any ? highest + 1 : 0;
  for (uint64_t old = next_index_ >= static_cast<uint64_t>(config_.max_pairs)
                          ? next_index_ - static_cast<uint64_t>(config_.max_pairs) + 1
                          : 0;
       old-- > 0;) {
    if (!RemovePair(PairDirectory(old).c_str()) && errno == ENOENT) break;  // older ones gone
  }
  for (Slot& s : slots_) {
    for (auto& p : s.pixels) {
      p.reset(new (std::nothrow) uint8_t[kMaxImagePixels]);
      if (!p) {
        return Status::Error(StatusCode::kResourceExhausted,
                             "record_dir: cannot allocate %d pair buffers", kRecordSlots);
      }
    }
    s.full = false;
  }
  stop_ = false;
  writer_ = std::thread([this] { WriterLoop(); });
  return Status::Ok();
}

void Recorder::Stop() {
  if (!writer_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  writer_.join();
}

bool Recorder::Submit(const hal::StereoFrame& frame, const protocol::ResultSet& set) {
  std::unique_lock<std::mutex> lock(mutex_);
  ++counters_.submitted;
  Slot* slot = nullptr;
  for (Slot& s : slots_) {
    if (!s.full && s.pixels[0]) {
      slot = &s;
      break;
    }
  }
  // On one camera the other side's view is empty: only the camera in use is recorded.
  const ConstGrayView* views[2] = {&frame.left, &frame.right};
  const bool present[2] = {frame.left.data != nullptr, frame.right.data != nullptr};
  const ConstGrayView& first = present[0] ? frame.left : frame.right;
  const int w = first.width;
  const int h = first.height;
  const bool sizes_agree =
      !(present[0] && present[1]) || (frame.right.width == w && frame.right.height == h);
  if (slot == nullptr || !(present[0] || present[1]) || w <= 0 || h <= 0 ||
      static_cast<size_t>(w) * static_cast<size_t>(h) > kMaxImagePixels || !sizes_agree) {
    ++counters_.dropped;
    return false;
  }
  // Rows one by one: camera buffers may have a stride.
  for (int side = 0; side < 2; ++side) {
    slot->present[side] = present[side];
    if (!present[side]) continue;
    for (int y = 0; y < h; ++y) {
      std::memcpy(slot->pixels[side].get() + static_cast<size_t>(y) * static_cast<size_t>(w),
                  &views[side]->at(0, y), static_cast<size_t>(w));
    }
  }
  slot->width = w;
  slot->height = h;
  slot->timestamp_ns[0] = frame.left_timestamp_ns;
  slot->timestamp_ns[1] = frame.right_timestamp_ns;
  slot->set = set;
  slot->index = next_index_++;
  slot->full = true;
  lock.unlock();
  cv_.notify_all();
  return true;
}

RecorderCounters Recorder::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

Recorder::PairPath Recorder::PairDirectory(uint64_t index) const {
  PairPath p;
  std::snprintf(p.text, sizeof(p.text), "%s/%08" PRIu64, config_.directory.c_str(),
                index % 100000000u);
  return p;
}

void Recorder::WriterLoop() {
  // The lowest priority: recording must never take time from recognition.
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
  while (true) {
    Slot* slot = nullptr;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [this] {
        if (stop_) return true;
        for (const Slot& s : slots_) {
          if (s.full) return true;
        }
        return false;
      });
      for (Slot& s : slots_) {
        if (s.full && (slot == nullptr || s.index < slot->index)) slot = &s;
      }
      if (slot == nullptr) return;  // stop, nothing left
    }
    const Status written = WritePair(*slot);  // the worker leaves a full slot alone
    const int error_number = errno != 0 ? errno : EIO;
    // Read before the slot is released: from then on the worker may fill it with the next pair.
    const uint64_t written_index = slot->index;
    bool report_failure = false, report_recovery = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      slot->full = false;
      if (written.ok()) {
        ++counters_.written;
        report_recovery = failing_;
        failing_ = false;
      } else {
        ++counters_.failed;
        report_failure = !failing_;
        failing_ = true;
      }
    }
    if (written.ok()) DeleteOld(written_index);
    if (report_failure && observer_ != nullptr) observer_->OnRecordFailed(error_number);
    if (report_recovery && observer_ != nullptr) observer_->OnRecordRecovered();
  }
}

Status Recorder::WritePair(const Slot& slot) {
  errno = 0;
  const PairPath dir_path = PairDirectory(slot.index);
  const char* dir = dir_path.c_str();
  if (mkdir(dir, 0755) != 0 && errno != EEXIST) {
    return Status::Error(StatusCode::kUnavailable, "%s: %s", dir, std::strerror(errno));
  }
  static char json[kResultJsonBytes];  // writer thread only
  const size_t n =
      FormatResultJson(slot.set, config_.output_frame, config_.background, config_.model_names,
                       config_.model_count, slot.timestamp_ns, json, sizeof(json));
  Status s = Status::Ok();
  for (int side = 0; side < 2 && s.ok(); ++side) {
    if (!slot.present[side]) continue;
    const ConstGrayView view{slot.pixels[side].get(), slot.width, slot.height, slot.width};
    const char* side_name = side == 0 ? "left" : "right";
    char name[16];
    std::snprintf(name, sizeof(name), "%s.%s", side_name, config_.pgm ? "pgm" : "png");
    const Path path(dir, name);
    s = config_.pgm ? hal::WritePgm(path.c_str(), view) : hal::WritePng(path.c_str(), view);
  }
  if (s.ok() && (n == 0 || !WriteFile(Path(dir, "result.json").c_str(), json, n))) {
    s = Status::Error(StatusCode::kUnavailable, "%s/result.json: %s", dir,
                      std::strerror(errno != 0 ? errno : EIO));
  }
  if (!s.ok()) {
    const int kept = errno;
    (void)RemovePair(dir);  // no half-written pair for a replay to trip over
    errno = kept;
  }
  return s;
}

void Recorder::DeleteOld(uint64_t written_index) {
  const uint64_t keep = static_cast<uint64_t>(config_.max_pairs);
  if (written_index < keep) return;
  if (RemovePair(PairDirectory(written_index - keep).c_str())) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++counters_.deleted;
  }
}

}  // namespace sh::fw
