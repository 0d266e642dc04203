// What the commissioning page shows of the last result: the result set, the pair it came from
// (reduced to at most kLiveMaxWidth x kLiveMaxHeight) and the models it names. The worker
// publishes each result through OnResult without waiting and without the heap: the buffers exist
// from Init, and when the server thread is reading the snapshot the worker leaves it as it is
// (counted as skipped) rather than wait for the lock. The server thread copies out under the
// lock and encodes outside it.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "firmware/firmware_core.hpp"
#include "firmware/result_codec.hpp"
#include "firmware/web/pair_capture.hpp"
#include "hal/camera.hpp"
#include "recog/base/status.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/model/model.hpp"

namespace sh::fw::web {

// One camera's reduced image as the page receives it.
struct LiveImage {
  std::vector<uint8_t> pixels;  // width x height, packed rows
  int width = 0;
  int height = 0;
  int scale = 1;  // full-size pixels per live pixel
};

struct LiveResult {
  protocol::ResultSet set;     // poses in the output frame, as sent
  uint64_t results = 0;        // result sets published since boot; 0 = none yet
  int64_t published_ns = 0;    // CLOCK_MONOTONIC
  bool has_frame = false;      // the set came with images (not a capture error)
  int full_width[2] = {0, 0};  // of the frames, per side (0 = that camera was not in use)
  int full_height[2] = {0, 0};
};

class LiveSnapshot final : public CoreObserver {
 public:
  // Allocates the buffers (boot). `camera_T_out` maps the output frame back into the left
  // camera, where the overlays are drawn.
  Status Init(const RigidTransform& camera_T_out);

  // CoreObserver (worker thread): never waits, never allocates.
  void OnResult(const protocol::ResultSet& set, const hal::StereoFrame* frame) override;
  // Copies the models (boot and a cleared data fault: the worker may wait here).
  void OnDataLoaded(const ModelSet& models) override;

  // Server thread.
  LiveResult Result() const;
  // The image of `side` (0 left, 1 right) of the last result; false when there is none.
  bool Image(int side, LiveImage* out) const;
  // The models as last loaded: count, and a model by id (nullptr beyond the count).
  size_t model_count() const;
  bool CopyModel(size_t id, Model* out) const;
  const RigidTransform& camera_T_out() const { return camera_T_out_; }
  // Boot, before the core runs: every result's full frames are also offered to `capture` (the
  // calibration helper), which copies them only when armed.
  void SetCapture(PairCapture* capture) { capture_ = capture; }
  uint64_t skipped() const { return skipped_.load(); }

 private:
  // Worker: the frame of one side reduced into buffer `side`.
  void Reduce(ConstGrayView image, int side);

  RigidTransform camera_T_out_;
  mutable std::mutex mutex_;
  LiveResult result_;
  std::unique_ptr<uint8_t[]> pixels_[2];
  int width_[2] = {0, 0}, height_[2] = {0, 0}, scale_[2] = {1, 1};
  std::unique_ptr<Model[]> models_;
  size_t model_count_ = 0;
  std::atomic<uint64_t> skipped_{0};
  PairCapture* capture_ = nullptr;
};

// Pixels per live pixel for a frame of width x height: the smallest power of two that fits it
// into kLiveMaxWidth x kLiveMaxHeight.
int LiveScale(int width, int height);

}  // namespace sh::fw::web
