#include "hal/sim/sim_camera.hpp"

#include <new>

namespace sh::hal {
namespace {

constexpr StereoSide kSides[2] = {StereoSide::kLeft, StereoSide::kRight};
int Index(StereoSide side) { return static_cast<int>(side); }

}  // namespace

SimCamera::SimCamera(FrameSource* source, const SimCameraConfig& config)
    : source_(source), config_(config) {}

SimCamera::~SimCamera() { (void)Stop(); }

Status SimCamera::Start() {
  if (started_) return Status::Error(StatusCode::kFailedPrecondition, "sim camera already started");
  if (source_ == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "sim camera has no frame source");
  }
  if (config_.frame_period_ns <= 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "sim camera frame period must be positive (got %lld ns)",
                         static_cast<long long>(config_.frame_period_ns));
  }
  if (config_.jitter_ns < 0) {
    return Status::Error(StatusCode::kInvalidArgument, "sim camera jitter must not be negative");
  }
  if (config_.fault_starts < 0 || starts_ < config_.fault_starts) {  // this start's faults
    for (const StereoSide side : kSides) {
      const bool absent = side == StereoSide::kLeft ? config_.left_absent : config_.right_absent;
      const CaptureMode without =
          side == StereoSide::kLeft ? CaptureMode::kRightOnly : CaptureMode::kLeftOnly;
      if (absent && mode_ != without) {
        return Status::Error(StatusCode::kNotFound, "sim camera: no %s camera connected",
                             StereoSideName(side));
      }
    }
  }
  SH_RETURN_IF_ERROR(pairer_.Configure(config_.pairing));
  int width = 0;
  int height = 0;
  SH_RETURN_IF_ERROR(source_->Open(&width, &height));
  if (width <= 0 || height <= 0 || width > kMaxImageWidth || height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "frame source size %dx%d outside 1x1..%dx%d",
                         width, height, kMaxImageWidth, kMaxImageHeight);
  }
  const FrameFormat format = source_->format();
  if (format != FrameFormat::kGray8 && format != FrameFormat::kNv12) {
    return Status::Error(StatusCode::kUnimplemented, "sim camera: frame source format %s",
                         FrameFormatName(format));
  }
  // All buffers in one block, allocated here and never again while streaming. NV12: the chroma
  // pairs follow the Y plane, ceil(w/2) x ceil(h/2) of them, two bytes each.
  size_t frame_bytes = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (format == FrameFormat::kNv12) {
    frame_bytes += 2 * static_cast<size_t>((width + 1) / 2) * static_cast<size_t>((height + 1) / 2);
  }
  const size_t total = frame_bytes * kSimBuffersPerSide * 2;
  if (width != width_ || height != height_ || frame_bytes != frame_bytes_ || !memory_) {
    memory_.reset(new (std::nothrow) uint8_t[total]);
    if (!memory_) {
      return Status::Error(StatusCode::kResourceExhausted,
                           "sim camera could not allocate %zu bytes of frame buffers", total);
    }
  }
  width_ = width;
  height_ = height;
  format_ = format;
  frame_bytes_ = frame_bytes;
  for (int s = 0; s < 2; ++s) {
    SidePool& pool = pools_[s];
    for (size_t i = 0; i < kSimBuffersPerSide; ++i) {
      pool.buffers[i] =
          memory_.get() + (static_cast<size_t>(s) * kSimBuffersPerSide + i) * frame_bytes;
      pool.free_ids[i] = static_cast<uint32_t>(i);
    }
    pool.free_count = kSimBuffersPerSide;
    delivered_[s] = 0;
  }
  RecycleList recycled;
  pairer_.SetMode(mode_);
  pairer_.Reset(recycled);  // nothing queued yet: buffers were just handed to the pools
  next_frame_ = 0;
  no_buffer_drops_ = 0;
  jitter_state_ = config_.jitter_seed == 0 ? 1u : config_.jitter_seed;
  end_of_stream_ = Status::Ok();
  holding_ = false;
  started_ = true;
  ++starts_;
  return Status::Ok();
}

Status SimCamera::SetCaptureMode(CaptureMode mode) {
  mode_ = mode;  // read by the next Start()
  return Status::Ok();
}

bool SimCamera::FaultsActive() const {
  return config_.fault_starts < 0 || starts_ <= config_.fault_starts;
}

Status SimCamera::Stop() {
  if (!started_) return Status::Ok();
  pairer_.Close(Status::Error(StatusCode::kUnavailable, "sim camera stopped"));
  RecycleList recycled;
  pairer_.Drain(recycled);
  GiveBack(recycled);
  holding_ = false;
  started_ = false;
  return Status::Ok();
}

GrayView SimCamera::BufferView(StereoSide side, uint32_t buffer_id) const {
  return GrayView{pools_[Index(side)].buffers[buffer_id], width_, height_, width_};
}

ImageView<CbCr8> SimCamera::ChromaView(StereoSide side, uint32_t buffer_id) const {
  // The chroma pairs start right after the Y plane: 2-byte CbCr8 at any even or odd offset is
  // fine (alignment 1).
  uint8_t* chroma = pools_[Index(side)].buffers[buffer_id] + size_t(width_) * size_t(height_);
  const int cw = (width_ + 1) / 2, ch = (height_ + 1) / 2;
  return ImageView<CbCr8>{reinterpret_cast<CbCr8*>(chroma), cw, ch, cw};
}

FrameView SimCamera::FrameOf(StereoSide side, uint32_t buffer_id) const {
  const GrayView y = BufferView(side, buffer_id);
  if (format_ != FrameFormat::kNv12) return FrameView::Gray(y);
  const ImageView<CbCr8> c = ChromaView(side, buffer_id);
  return FrameView::Nv12(y, ImageView<const CbCr8>{c.data, c.width, c.height, c.stride},
                         YcbcrEncoding::kRec601, YcbcrRange::kFull);
}

void SimCamera::GiveBack(StereoSide side, uint32_t buffer_id) {
  SidePool& pool = pools_[Index(side)];
  assert(pool.free_count < kSimBuffersPerSide);
  pool.free_ids[pool.free_count++] = buffer_id;
}

void SimCamera::GiveBack(const Vector<RecycledFrame>& recycled) {
  for (const RecycledFrame& r : recycled) GiveBack(r.side, r.frame.buffer_id);
}

bool SimCamera::SideStopped(StereoSide side) const {
  const int64_t limit =
      side == StereoSide::kLeft ? config_.left_stop_after : config_.right_stop_after;
  return FaultsActive() && limit >= 0 && delivered_[Index(side)] >= static_cast<uint64_t>(limit);
}

int64_t SimCamera::Timestamp(StereoSide side, uint64_t frame_index) {
  int64_t t_ns =
      config_.first_timestamp_ns + static_cast<int64_t>(frame_index) * config_.frame_period_ns;
  if (side == StereoSide::kRight) {
    const int64_t elapsed_ns = t_ns - config_.first_timestamp_ns;
    // ppb applied in two steps (us, then ppb/1000) so that hours of frames do not overflow.
    t_ns += config_.right_offset_ns + (elapsed_ns / 1000) * config_.right_drift_ppb / 1'000'000;
  }
  if (config_.jitter_ns > 0) {
    // xorshift32: cheap, deterministic per seed, good enough for timing noise.
    jitter_state_ ^= jitter_state_ << 13;
    jitter_state_ ^= jitter_state_ >> 17;
    jitter_state_ ^= jitter_state_ << 5;
    const uint64_t span = static_cast<uint64_t>(2 * config_.jitter_ns + 1);
    t_ns += static_cast<int64_t>(jitter_state_ % span) - config_.jitter_ns;
  }
  return t_ns;
}

Status SimCamera::ProduceFrame() {
  const uint64_t n = next_frame_++;
  SidePool& lpool = pools_[0];
  SidePool& rpool = pools_[1];
  if (lpool.free_count == 0 || rpool.free_count == 0) {
    // Timestamps drawn as for a captured frame, so the jitter sequence of the others stays.
    Timestamp(StereoSide::kLeft, n);
    Timestamp(StereoSide::kRight, n);
    ++no_buffer_drops_;
    return Status::Ok();
  }
  const uint32_t ids[2] = {lpool.free_ids[--lpool.free_count], rpool.free_ids[--rpool.free_count]};
  // Timestamps are drawn for both sides of every frame, so dropping frames does not change the
  // jitter sequence of the others.
  const int64_t t_ns[2] = {Timestamp(StereoSide::kLeft, n), Timestamp(StereoSide::kRight, n)};
  const Status rendered =
      format_ == FrameFormat::kNv12
          ? source_->RenderNv12(n,
                                Nv12Target{BufferView(StereoSide::kLeft, ids[0]),
                                           ChromaView(StereoSide::kLeft, ids[0])},
                                Nv12Target{BufferView(StereoSide::kRight, ids[1]),
                                           ChromaView(StereoSide::kRight, ids[1])})
          : source_->Render(n, BufferView(StereoSide::kLeft, ids[0]),
                            BufferView(StereoSide::kRight, ids[1]));
  if (!rendered.ok()) {
    GiveBack(StereoSide::kLeft, ids[0]);
    GiveBack(StereoSide::kRight, ids[1]);
    if (rendered.code() != StatusCode::kOutOfRange) pairer_.ReportError(StereoSide::kLeft);
    return rendered;
  }
  RecycleList recycled;
  for (StereoSide side : kSides) {
    const int i = Index(side);
    const uint32_t every =
        side == StereoSide::kLeft ? config_.drop_left_every : config_.drop_right_every;
    const bool dropped = FaultsActive() && every > 0 && (n + 1) % every == 0;
    if (SideStopped(side) || dropped) {
      GiveBack(side, ids[i]);
      continue;
    }
    ++delivered_[i];
    TimestampedFrame frame;
    frame.view = BufferView(side, ids[i]);
    frame.frame = FrameOf(side, ids[i]);
    frame.timestamp_ns = t_ns[i];
    frame.sequence = static_cast<uint32_t>(n);
    frame.buffer_id = ids[i];
    pairer_.Push(side, frame, recycled);
  }
  GiveBack(recycled);
  return Status::Ok();
}

Status SimCamera::Capture(StereoFrame* out, int timeout_ms) {
  if (out == nullptr) return Status::Error(StatusCode::kInvalidArgument, "Capture needs an output");
  if (!started_) return Status::Error(StatusCode::kFailedPrecondition, "sim camera not started");
  if (timeout_ms < 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "capture timeout must not be negative (got %d ms)", timeout_ms);
  }
  Release();
  FramePair pair;
  bool have_pair = false;
  for (int produced = 0;; ++produced) {
    if (pairer_.TryTakePair(&pair)) {
      have_pair = true;
      break;
    }
    if (!end_of_stream_.ok()) return end_of_stream_;
    // In a one-side mode only the used side matters.
    const bool left_stopped = mode_ == CaptureMode::kRightOnly || SideStopped(StereoSide::kLeft);
    const bool right_stopped = mode_ == CaptureMode::kLeftOnly || SideStopped(StereoSide::kRight);
    if (produced == kSimFramesPerCapture || (left_stopped && right_stopped)) break;
    const Status s = ProduceFrame();
    if (s.code() == StatusCode::kOutOfRange) {
      end_of_stream_ = s;  // pairs already queued are still delivered first
    } else if (!s.ok()) {
      return s;
    }
  }
  if (!have_pair) SH_RETURN_IF_ERROR(pairer_.WaitPair(timeout_ms, &pair));
  held_ = pair;
  holding_ = true;
  *out = ToStereoFrame(pair);
  return Status::Ok();
}

void SimCamera::Release() {
  if (!holding_) return;
  // The empty half of a one-side frame holds no buffer.
  if (held_.left.view.data != nullptr) GiveBack(StereoSide::kLeft, held_.left.buffer_id);
  if (held_.right.view.data != nullptr) GiveBack(StereoSide::kRight, held_.right.buffer_id);
  holding_ = false;
}

CameraStats SimCamera::stats() const {
  CameraStats stats = pairer_.stats();
  stats.no_buffer_drops = no_buffer_drops_;
  return stats;
}

}  // namespace sh::hal
