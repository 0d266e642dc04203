#include "hal/stereo_pairing.hpp"

#include <chrono>

namespace sh::hal {
namespace {

int64_t AbsDiff(int64_t a, int64_t b) { return a > b ? a - b : b - a; }

// A full recycle list means kMaxRecycledPerCall is wrong; losing the buffer would starve a
// camera, so this is an invariant rather than an input error.
void Recycle(Vector<RecycledFrame>& recycled, StereoSide side, const TimestampedFrame& frame) {
  const bool stored = recycled.push_back(RecycledFrame{side, frame});
  assert(stored && "recycle list smaller than kMaxRecycledPerCall");
  (void)stored;
}

StereoSide Other(StereoSide side) {
  return side == StereoSide::kLeft ? StereoSide::kRight : StereoSide::kLeft;
}

}  // namespace

const char* StereoSideName(StereoSide side) { return side == StereoSide::kLeft ? "left" : "right"; }

const char* CaptureModeName(CaptureMode mode) {
  switch (mode) {
    case CaptureMode::kLeftOnly:
      return "left only";
    case CaptureMode::kRightOnly:
      return "right only";
    case CaptureMode::kStereo:
      break;
  }
  return "stereo";
}

void StereoPairer::SetMode(CaptureMode mode) {
  std::lock_guard<std::mutex> lock(mu_);
  pending_mode_ = mode;
}

Status StereoPairer::Configure(const PairingConfig& config) {
  if (config.tolerance_ns < 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "stereo pairing tolerance must not be negative (got %lld ns)",
                         static_cast<long long>(config.tolerance_ns));
  }
  std::lock_guard<std::mutex> lock(mu_);
  pending_config_ = config;
  return Status::Ok();
}

void StereoPairer::Reset(Vector<RecycledFrame>& recycled) {
  std::lock_guard<std::mutex> lock(mu_);
  DrainLocked(recycled);
  config_ = pending_config_;
  mode_ = pending_mode_;
  for (SideState& s : sides_) s = SideState{};
  stats_ = CameraStats{};
  next_pair_index_ = 0;
  open_ = true;
  close_reason_ = Status::Ok();
}

void StereoPairer::Push(StereoSide side, const TimestampedFrame& frame,
                        Vector<RecycledFrame>& recycled) {
  std::lock_guard<std::mutex> lock(mu_);
  if (!open_) {
    Recycle(recycled, side, frame);
    return;
  }
  SideState& s = state(side);
  if (s.seen_any && frame.timestamp_ns <= s.newest_ns) {
    // Each side's clock only moves forward; a step back would break the "can never be paired"
    // rule, so the frame is refused.
    ++stats_.errors;
    Recycle(recycled, side, frame);
    return;
  }
  s.seen_any = true;
  s.newest_ns = frame.timestamp_ns;
  ++s.since_last_pair;
  if (mode_ != CaptureMode::kStereo) {
    const StereoSide used =
        mode_ == CaptureMode::kLeftOnly ? StereoSide::kLeft : StereoSide::kRight;
    if (side != used) {
      Recycle(recycled, side, frame);
      return;
    }
  }
  if (s.queue.full()) {
    Recycle(recycled, side, s.queue.pop());
    ++(side == StereoSide::kLeft ? stats_.left_overflow_drops : stats_.right_overflow_drops);
  }
  s.queue.push(frame);
  MatchLocked(recycled);
}

void StereoPairer::ReportError(StereoSide side) {
  std::lock_guard<std::mutex> lock(mu_);
  ++stats_.errors;
}

void StereoPairer::Close(const Status& reason) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    if (!open_) return;
    open_ = false;
    close_reason_ =
        reason.ok() ? Status::Error(StatusCode::kUnavailable, "stereo camera stopped") : reason;
  }
  ready_cv_.notify_all();
}

void StereoPairer::Drain(Vector<RecycledFrame>& recycled) {
  std::lock_guard<std::mutex> lock(mu_);
  DrainLocked(recycled);
}

void StereoPairer::DrainLocked(Vector<RecycledFrame>& recycled) {
  for (int i = 0; i < 2; ++i) {
    while (!sides_[i].queue.empty()) {
      Recycle(recycled, static_cast<StereoSide>(i), sides_[i].queue.pop());
    }
  }
  while (ready_.count > 0) {
    RecyclePairLocked(ready_.items[ready_.head], recycled);
    ready_.head = (ready_.head + 1) % kStereoPairDepth;
    --ready_.count;
  }
}

void StereoPairer::DropFrontLocked(StereoSide side, Vector<RecycledFrame>& recycled) {
  Recycle(recycled, side, state(side).queue.pop());
  ++(side == StereoSide::kLeft ? stats_.left_unpaired_drops : stats_.right_unpaired_drops);
}

void StereoPairer::RecyclePairLocked(const FramePair& pair, Vector<RecycledFrame>& recycled) {
  // A one-side pair's empty half holds no buffer.
  if (mode_ != CaptureMode::kRightOnly) Recycle(recycled, StereoSide::kLeft, pair.left);
  if (mode_ != CaptureMode::kLeftOnly) Recycle(recycled, StereoSide::kRight, pair.right);
}

void StereoPairer::MatchLocked(Vector<RecycledFrame>& recycled) {
  if (mode_ != CaptureMode::kStereo) {
    // Only the used side ever has frames queued: each is delivered alone.
    while (!state(StereoSide::kLeft).queue.empty() || !state(StereoSide::kRight).queue.empty()) {
      EmitPairLocked(recycled);
    }
    return;
  }
  const int64_t tol = config_.tolerance_ns;
  for (;;) {
    SideState& left = state(StereoSide::kLeft);
    SideState& right = state(StereoSide::kRight);
    if (left.queue.empty() && right.queue.empty()) return;
    if (left.queue.empty() || right.queue.empty()) {
      // Only one side has frames: they are stale if the other side has already delivered a frame
      // newer than them by more than the tolerance (its future frames are newer still).
      const StereoSide waiting = left.queue.empty() ? StereoSide::kRight : StereoSide::kLeft;
      const SideState& w = state(waiting);
      const SideState& o = state(Other(waiting));
      if (o.seen_any && w.queue.at(0).timestamp_ns + tol < o.newest_ns) {
        DropFrontLocked(waiting, recycled);
        continue;
      }
      return;
    }
    const TimestampedFrame& l = left.queue.at(0);
    const TimestampedFrame& r = right.queue.at(0);
    const int64_t l_minus_r = l.timestamp_ns - r.timestamp_ns;
    if (l_minus_r < -tol) {
      DropFrontLocked(StereoSide::kLeft, recycled);
      continue;
    }
    if (l_minus_r > tol) {
      DropFrontLocked(StereoSide::kRight, recycled);
      continue;
    }
    // Within tolerance. A closer partner already queued wins; this only matters when the
    // tolerance is close to half the frame period or during bursts.
    const int64_t gap = AbsDiff(l.timestamp_ns, r.timestamp_ns);
    if (left.queue.size() > 1 && AbsDiff(left.queue.at(1).timestamp_ns, r.timestamp_ns) < gap) {
      DropFrontLocked(StereoSide::kLeft, recycled);
      continue;
    }
    if (right.queue.size() > 1 && AbsDiff(right.queue.at(1).timestamp_ns, l.timestamp_ns) < gap) {
      DropFrontLocked(StereoSide::kRight, recycled);
      continue;
    }
    EmitPairLocked(recycled);
  }
}

void StereoPairer::EmitPairLocked(Vector<RecycledFrame>& recycled) {
  if (ready_.count == kStereoPairDepth) {
    // The consumer fell behind: the oldest pair is the least useful one.
    RecyclePairLocked(ready_.items[ready_.head], recycled);
    ready_.head = (ready_.head + 1) % kStereoPairDepth;
    --ready_.count;
    ++stats_.pair_overflow_drops;
  }
  FramePair& slot = ready_.items[(ready_.head + ready_.count) % kStereoPairDepth];
  slot.left =
      mode_ == CaptureMode::kRightOnly ? TimestampedFrame{} : state(StereoSide::kLeft).queue.pop();
  slot.right =
      mode_ == CaptureMode::kLeftOnly ? TimestampedFrame{} : state(StereoSide::kRight).queue.pop();
  ++ready_.count;
  ++stats_.frames_paired;
  for (SideState& s : sides_) s.since_last_pair = 0;
  ready_cv_.notify_one();
}

Status StereoPairer::WaitPair(int timeout_ms, FramePair* out) {
  if (out == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "WaitPair needs an output pair");
  }
  if (timeout_ms < 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "capture timeout must not be negative (got %d ms)", timeout_ms);
  }
  std::unique_lock<std::mutex> lock(mu_);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (ready_.count == 0 && open_) {
    if (ready_cv_.wait_until(lock, deadline) == std::cv_status::timeout) break;
  }
  if (ready_.count > 0) {
    TakePairLocked(out);
    return Status::Ok();
  }
  if (!open_) return close_reason_;
  ++stats_.timeouts;
  return TimeoutStatusLocked(timeout_ms);
}

bool StereoPairer::TryTakePair(FramePair* out) {
  std::lock_guard<std::mutex> lock(mu_);
  if (out == nullptr || ready_.count == 0) return false;
  TakePairLocked(out);
  return true;
}

void StereoPairer::TakePairLocked(FramePair* out) {
  *out = ready_.items[ready_.head];
  out->pair_index = next_pair_index_++;
  ready_.head = (ready_.head + 1) % kStereoPairDepth;
  --ready_.count;
  ++stats_.pairs_delivered;
}

Status StereoPairer::TimeoutStatusLocked(int timeout_ms) const {
  const uint64_t n_left = sides_[0].since_last_pair;
  const uint64_t n_right = sides_[1].since_last_pair;
  if (n_left == 0 && n_right == 0) {
    return Status::Error(StatusCode::kDeadlineExceeded,
                         "no stereo pair within %d ms: both cameras silent since the last pair",
                         timeout_ms);
  }
  if (n_left == 0 || n_right == 0) {
    return Status::Error(StatusCode::kDeadlineExceeded,
                         "no stereo pair within %d ms: %s camera silent, %s camera delivered %llu "
                         "frames since the last pair",
                         timeout_ms, n_left == 0 ? "left" : "right", n_left == 0 ? "right" : "left",
                         static_cast<unsigned long long>(n_left == 0 ? n_right : n_left));
  }
  return Status::Error(StatusCode::kDeadlineExceeded,
                       "no stereo pair within %d ms: left %llu and right %llu frames since the "
                       "last pair, none within %lld us of each other (clock drift or skew?)",
                       timeout_ms, static_cast<unsigned long long>(n_left),
                       static_cast<unsigned long long>(n_right),
                       static_cast<long long>(config_.tolerance_ns / 1000));
}

void StereoPairer::CountTimeout() {
  std::lock_guard<std::mutex> lock(mu_);
  ++stats_.timeouts;
}

Result<StereoSide> StereoPairer::SilentSide() const {
  std::lock_guard<std::mutex> lock(mu_);
  const bool left_silent = sides_[0].since_last_pair == 0;
  const bool right_silent = sides_[1].since_last_pair == 0;
  if (left_silent == right_silent) {
    return Status::Error(StatusCode::kNotFound, "no single silent camera");
  }
  return left_silent ? StereoSide::kLeft : StereoSide::kRight;
}

CameraStats StereoPairer::stats() const {
  std::lock_guard<std::mutex> lock(mu_);
  return stats_;
}

}  // namespace sh::hal
