// Pairs left and right frames that arrive asynchronously from two free-running cameras.
//
// Producers (camera completion callbacks, one per side or one shared) Push() timestamped frames;
// the consumer WaitPair()s for the next left/right pair whose sensor timestamps differ by at most
// PairingConfig::tolerance_ns. Independent of any camera library so that it is tested on the host.
//
// Rules (timestamps of each side must increase; a frame that does not is counted as an error and
// handed back):
// - The oldest left and the oldest right frame are compared. If they are within tolerance they
//   form a pair, unless the next queued frame of either side is even closer to the partner (then
//   the farther one is dropped as unpaired).
// - A frame older than the other side's oldest queued frame (or, with that queue empty, than the
//   newest frame the other side ever delivered) by more than the tolerance can never be paired,
//   because each side's timestamps only grow: it is dropped and counted per side.
// - Each side's queue holds kStereoQueueDepth frames; when full, the oldest frame is dropped
//   (counted as overflow). Finished pairs wait in a queue of kStereoPairDepth; when the consumer
//   falls behind, the oldest pair is dropped (counted), so the consumer always gets the newest.
// Choose the tolerance below half the frame period, otherwise a frame may match two partners.
//
// Buffers are never owned here: every frame that leaves the pairer without being delivered is
// appended to the caller's `recycled` list so the backend can give the buffer back to its camera.
// Thread-safe (one mutex + condition variable); nothing allocates.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>

#include "hal/camera.hpp"
#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/image/image.hpp"

namespace sh::hal {

// Frames awaiting a partner, per side. Must cover the skew between the two completion callbacks
// (typically one frame) plus bursts; backends allocate at least this many buffers plus
// kStereoPairDepth + 2 per camera so that a full queue never starves a camera.
inline constexpr size_t kStereoQueueDepth = 4;
// Finished pairs awaiting the consumer. Small on purpose: old pairs are worthless for tracking.
inline constexpr size_t kStereoPairDepth = 2;

struct TimestampedFrame {
  ConstGrayView view;  // grey (StereoFrame::left)
  FrameView frame;     // the delivered format; empty: the grey view is the frame
  int64_t timestamp_ns = 0;
  uint32_t sequence = 0;
  uint32_t buffer_id = 0;  // backend-defined handle to find the buffer again when recycling it
};

struct RecycledFrame {
  StereoSide side = StereoSide::kLeft;
  TimestampedFrame frame;
};

// Most frames one call can hand back: both side queues, all queued pairs and the pushed frame.
inline constexpr size_t kMaxRecycledPerCall = 2 * kStereoQueueDepth + 2 * kStereoPairDepth + 1;
using RecycleList = Vector<RecycledFrame, kMaxRecycledPerCall>;

struct FramePair {
  TimestampedFrame left;
  TimestampedFrame right;
  uint64_t pair_index = 0;  // pairs delivered before this one since Reset()
};

// What a backend's Capture() hands out for a pair: the views, timestamps and counters, with the
// buffers still held by the backend until Release().
inline StereoFrame ToStereoFrame(const FramePair& pair) {
  StereoFrame frame;
  frame.left = pair.left.view;
  frame.right = pair.right.view;
  frame.left_frame =
      pair.left.frame.width() > 0 ? pair.left.frame : FrameView::Gray(pair.left.view);
  frame.right_frame =
      pair.right.frame.width() > 0 ? pair.right.frame : FrameView::Gray(pair.right.view);
  frame.left_timestamp_ns = pair.left.timestamp_ns;
  frame.right_timestamp_ns = pair.right.timestamp_ns;
  frame.left_sequence = pair.left.sequence;
  frame.right_sequence = pair.right.sequence;
  frame.pair_index = pair.pair_index;
  return frame;
}

struct PairingConfig {
  int64_t tolerance_ns = 2'000'000;  // 2 ms: well inside half a frame period up to 250 fps
};

class StereoPairer {
 public:
  StereoPairer() = default;
  StereoPairer(const StereoPairer&) = delete;
  StereoPairer& operator=(const StereoPairer&) = delete;

  // Rejects a negative tolerance. Takes effect at the next Reset().
  Status Configure(const PairingConfig& config);
  // One-side mode (kLeftOnly, kRightOnly): every frame of that side is a "pair" on its own, with
  // the other side's frame empty (a default TimestampedFrame, never handed back); frames pushed
  // for the
  // other side are handed straight back. Takes effect at the next Reset().
  void SetMode(CaptureMode mode);

  // Starts a new session: opens the pairer, zeroes the counters and hands back queued frames.
  void Reset(Vector<RecycledFrame>& recycled);

  // Producer side. A frame pushed while closed is handed straight back.
  void Push(StereoSide side, const TimestampedFrame& frame, Vector<RecycledFrame>& recycled);
  // Counts a frame the backend could not deliver (failed request, corrupt file).
  void ReportError(StereoSide side);
  // Ends the session: a waiting consumer wakes up; WaitPair() delivers the pairs still queued,
  // then returns `reason` (should be non-ok, e.g. kUnavailable "left camera disconnected").
  void Close(const Status& reason);
  // Hands back every queued frame and pair (use after Close() to recover all buffers).
  void Drain(Vector<RecycledFrame>& recycled);

  // Consumer side: waits up to timeout_ms (0 polls) for the next pair. kDeadlineExceeded names
  // the silent side; after Close() the close reason is returned.
  Status WaitPair(int timeout_ms, FramePair* out);
  // Takes the next pair if one is ready, without waiting or counting a timeout (for pull-based
  // backends that produce frames themselves).
  bool TryTakePair(FramePair* out);

  // Counts a consumer timeout that happened outside WaitPair (e.g. in a pull-based simulator).
  void CountTimeout();
  CameraStats stats() const;
  // The side that delivered nothing since the last pair while the other did; kNotFound when
  // both or neither did.
  Result<StereoSide> SilentSide() const;

 private:
  template <size_t N>
  struct Ring {
    bool empty() const { return count == 0; }
    bool full() const { return count == N; }
    size_t size() const { return count; }
    const TimestampedFrame& at(size_t i) const { return items[(head + i) % N]; }
    void push(const TimestampedFrame& f) {
      items[(head + count) % N] = f;
      ++count;
    }
    TimestampedFrame pop() {
      const TimestampedFrame f = items[head];
      head = (head + 1) % N;
      --count;
      return f;
    }
    TimestampedFrame items[N];
    size_t head = 0;
    size_t count = 0;
  };
  struct PairRing {
    FramePair items[kStereoPairDepth];
    size_t head = 0;
    size_t count = 0;
  };

  struct SideState {
    Ring<kStereoQueueDepth> queue;
    bool seen_any = false;
    int64_t newest_ns = 0;  // newest timestamp ever pushed on this side
    uint64_t since_last_pair = 0;
  };

  // All below run with mu_ held.
  void MatchLocked(Vector<RecycledFrame>& recycled);
  void EmitPairLocked(Vector<RecycledFrame>& recycled);
  void DropFrontLocked(StereoSide side, Vector<RecycledFrame>& recycled);
  void DrainLocked(Vector<RecycledFrame>& recycled);
  void TakePairLocked(FramePair* out);
  void RecyclePairLocked(const FramePair& pair, Vector<RecycledFrame>& recycled);
  Status TimeoutStatusLocked(int timeout_ms) const;
  SideState& state(StereoSide side) { return sides_[static_cast<int>(side)]; }

  mutable std::mutex mu_;
  std::condition_variable ready_cv_;
  PairingConfig config_;
  PairingConfig pending_config_;
  CaptureMode mode_ = CaptureMode::kStereo;
  CaptureMode pending_mode_ = CaptureMode::kStereo;
  SideState sides_[2];
  PairRing ready_;
  bool open_ = false;
  Status close_reason_ =
      Status::Error(StatusCode::kFailedPrecondition, "stereo pairing not started");
  uint64_t next_pair_index_ = 0;
  CameraStats stats_;
};

}  // namespace sh::hal
