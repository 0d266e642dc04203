// Recording of triggered pairs with their results (config record_dir, record_max), so that a
// failure on the line can be reproduced on a desk: `stereohash-fw-sim` with camera = directory on
// the recording replays it, `stereohash recognize --scene DIR/<n>` recognises one pair.
//
//   DIR/calib.yaml           the calibration in use (written at start)
//   DIR/table.yaml           the table pose, if the configuration gives one
//   DIR/rig_table.yaml       the table the board knows without configuration (the simulator's
//                            rendered table): it bounds the working volume and serves the
//                            one-camera fallback, and the replay takes it in that role only
//   DIR/settings.conf        the recognition settings in use, as firmware configuration lines
//                            (recorded_settings.hpp: preset, working volume, table estimate,
//                            one-camera fallback): the replays recognise with them
//   DIR/<n>/left.png         n: 8 digits, counting up across restarts; the last record_max kept
//   DIR/<n>/right.png        (.pgm with record_format = pgm: several times faster to write,
//                            twice as large); on one camera only the image of the camera in use
//   DIR/<n>/result.json      the result set as sent (sequence, request id, status, time, frame,
//                            objects with model, pose, score), image timestamps, the
//                            detector preset (background)
//
// The worker only copies the pair and the set into one of kRecordSlots preallocated slots
// (Submit: no heap, no I/O, never waits); a writer thread at the lowest priority (nice 19)
// encodes and writes them. A full slot ring drops the pair (counted). A write error (full disk,
// read-only medium) is reported to the observer as a warning, and its end when a later pair is
// written again; the oldest pairs beyond record_max are deleted.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "firmware/result_codec.hpp"
#include "hal/camera.hpp"
#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::fw {

// Pairs the worker can hand over before the writer catches up (each slot holds two images of
// up to kMaxImageWidth x kMaxImageHeight and a result set: 2.6 MB).
inline constexpr int kRecordSlots = 3;

class RecorderObserver {
 public:
  virtual ~RecorderObserver() = default;
  // From the writer thread: a pair could not be written (errno), or writing works again.
  virtual void OnRecordFailed(int error_number) = 0;
  virtual void OnRecordRecovered() = 0;
};

struct RecorderConfig {
  std::string directory;
  int max_pairs = 100;
  bool pgm = false;                     // raw PGM instead of PNG
  const char* output_frame = "camera";  // name written into result.json
  // The detector preset the results were recognised with, as the `background` key's value: a
  // replay with another preset finds other edges and so other poses.
  const char* background = "auto";
  // settings.conf's text (RecordedSettings): every setting that shaped the results.
  std::string settings;
  // The board's own table (rig_table.yaml), or nullptr: none, or the table is configured.
  const RigidTransform* rig_T_table = nullptr;
  const char* const* model_names = nullptr;
  int model_count = 0;
};

struct RecorderCounters {
  uint64_t submitted = 0;
  uint64_t written = 0;
  uint64_t dropped = 0;  // slot ring full
  uint64_t failed = 0;   // write errors
  uint64_t deleted = 0;  // old pairs removed to keep max_pairs
};

class Recorder {
 public:
  Recorder() = default;
  ~Recorder() { Stop(); }
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Creates the directory if needed, writes calib.yaml (and table.yaml), allocates the slots
  // and starts the writer. Errors name the directory.
  Status Start(const RecorderConfig& config, const StereoCalibration& calibration,
               const RigidTransform* left_T_table, RecorderObserver* observer);
  // Writes what was submitted, then joins the writer.
  void Stop();

  // Worker thread: copies the pair and the set; false if every slot is still being written.
  bool Submit(const hal::StereoFrame& frame, const protocol::ResultSet& set);

  RecorderCounters counters() const;
  uint64_t next_index() const { return next_index_; }
  // The errno of the last failed Start() (ENOTDIR, EACCES, ...), for the EMCY detail; EIO when
  // the failure had none.
  int start_error() const { return start_error_; }

 private:
  Status StartWriting(const StereoCalibration& calibration, const RigidTransform* left_T_table);

  int start_error_ = 0;
  struct Slot {
    std::unique_ptr<uint8_t[]> pixels[2];
    int width = 0, height = 0;
    int64_t timestamp_ns[2] = {0, 0};
    bool present[2] = {false, false};  // false: that camera was not in use (one-camera sets)
    protocol::ResultSet set;
    uint64_t index = 0;
    bool full = false;  // submitted, not yet written
  };

  struct PairPath {
    char text[512] = {};
    const char* c_str() const { return text; }
  };

  void WriterLoop();
  Status WritePair(const Slot& slot);
  void DeleteOld(uint64_t written_index);
  PairPath PairDirectory(uint64_t index) const;

  RecorderConfig config_;
  RecorderObserver* observer_ = nullptr;
  Slot slots_[kRecordSlots];
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  bool stop_ = false;
  bool failing_ = false;     // writer: last write failed
  uint64_t next_index_ = 0;  // worker side, under mutex_
  RecorderCounters counters_;
  std::thread writer_;
};

// result.json of a set into out[0..capacity): sequence, request id, status, processing time,
// output frame, detector preset (`background`), objects (model id and name, instance, score,
// t_mm, q_wxyz), image timestamps. Returns the length, or 0 if it did not fit.
size_t FormatResultJson(const protocol::ResultSet& set, const char* output_frame,
                        const char* background, const char* const* model_names, int model_count,
                        const int64_t timestamp_ns[2], char* out, size_t capacity);

}  // namespace sh::fw
