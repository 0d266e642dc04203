#include "hal/sim/sim_camera.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <vector>

namespace sh::hal {
namespace {

constexpr int64_t kMs = 1'000'000;

// Pixel (x, y) of frame n: left = n + x + 2y, right = that + 100 (mod 256), so a delivered pair
// reveals which frame each side came from.
uint8_t Pattern(uint64_t n, int x, int y, bool right) {
  return static_cast<uint8_t>(n + static_cast<uint64_t>(x) + 2 * static_cast<uint64_t>(y) +
                              (right ? 100 : 0));
}

class PatternSource : public FrameSource {
 public:
  PatternSource(int width, int height) : width_(width), height_(height) {}
  Status Open(int* width, int* height) override {
    *width = width_;
    *height = height_;
    return Status::Ok();
  }
  Status Render(uint64_t n, GrayView left, GrayView right) override {
    ++renders;
    if (n == fail_at) {
      return Status::Error(StatusCode::kDataLoss, "frame %llu is corrupt",
                           static_cast<unsigned long long>(n));
    }
    if (end_after >= 0 && n >= static_cast<uint64_t>(end_after)) {
      return Status::Error(StatusCode::kOutOfRange, "end of pattern");
    }
    for (int y = 0; y < left.height; ++y) {
      for (int x = 0; x < left.width; ++x) {
        left.at(x, y) = Pattern(n, x, y, false);
        right.at(x, y) = Pattern(n, x, y, true);
      }
    }
    return Status::Ok();
  }
  uint64_t fail_at = ~uint64_t{0};
  int64_t end_after = -1;
  int renders = 0;

 private:
  int width_;
  int height_;
};

// Frame index a view shows, checked over every pixel; -1 if the view is not a pattern frame.
int64_t FrameShown(const ConstGrayView& v, bool right) {
  const uint64_t n = static_cast<uint8_t>(v.at(0, 0) - (right ? 100 : 0));
  for (int y = 0; y < v.height; ++y) {
    for (int x = 0; x < v.width; ++x) {
      if (v.at(x, y) != Pattern(n, x, y, right)) return -1;
    }
  }
  return static_cast<int64_t>(n);
}

TEST(CameraSim, CaptureBeforeStartIsRefused) {
  PatternSource source(8, 6);
  SimCamera cam(&source, SimCameraConfig{});
  StereoFrame f;
  EXPECT_EQ(cam.Capture(&f, 0).code(), StatusCode::kFailedPrecondition);
}

TEST(CameraSim, RefusesOversizedSourceAndBadConfig) {
  PatternSource big(kMaxImageWidth + 1, 10);
  SimCamera cam(&big, SimCameraConfig{});
  EXPECT_EQ(cam.Start().code(), StatusCode::kOutOfRange);
  PatternSource ok(8, 6);
  SimCameraConfig bad;
  bad.frame_period_ns = 0;
  SimCamera cam2(&ok, bad);
  EXPECT_EQ(cam2.Start().code(), StatusCode::kInvalidArgument);
  SimCamera cam3(nullptr, SimCameraConfig{});
  EXPECT_EQ(cam3.Start().code(), StatusCode::kInvalidArgument);
}

TEST(CameraSim, DeliversSourceFramesWithSyntheticTimestamps) {
  PatternSource source(16, 9);
  SimCameraConfig config;
  SimCamera cam(&source, config);
  ASSERT_TRUE(cam.Start().ok());
  EXPECT_EQ(cam.Start().code(), StatusCode::kFailedPrecondition);
  // Many more frames than buffers: buffers must come back on every Capture.
  constexpr int kFrames = 3 * static_cast<int>(kSimBuffersPerSide) + 5;
  for (int i = 0; i < kFrames; ++i) {
    StereoFrame f;
    const Status s = cam.Capture(&f, 100);
    ASSERT_TRUE(s.ok()) << s.message();
    ASSERT_EQ(f.left.width, 16);
    ASSERT_EQ(f.right.height, 9);
    EXPECT_EQ(FrameShown(f.left, false), i);
    EXPECT_EQ(FrameShown(f.right, true), i);
    EXPECT_EQ(f.left_sequence, static_cast<uint32_t>(i));
    EXPECT_EQ(f.right_sequence, static_cast<uint32_t>(i));
    EXPECT_EQ(f.pair_index, static_cast<uint64_t>(i));
    EXPECT_EQ(f.left_timestamp_ns, config.first_timestamp_ns + i * config.frame_period_ns);
    EXPECT_EQ(f.right_timestamp_ns, f.left_timestamp_ns);
    if (i % 2 == 0) cam.Release();
  }
  const CameraStats s = cam.stats();
  EXPECT_EQ(s.pairs_delivered, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(s.errors, 0u);
  EXPECT_TRUE(cam.Stop().ok());
  StereoFrame f;
  EXPECT_EQ(cam.Capture(&f, 0).code(), StatusCode::kFailedPrecondition);
  // Restart begins a new session.
  ASSERT_TRUE(cam.Start().ok());
  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  EXPECT_EQ(f.pair_index, 0u);
  EXPECT_EQ(cam.stats().pairs_delivered, 1u);
}

TEST(CameraSim, RightCameraStoppingTimesOutNamingIt) {
  PatternSource source(8, 6);
  SimCameraConfig config;
  config.right_stop_after = 3;
  SimCamera cam(&source, config);
  ASSERT_TRUE(cam.Start().ok());
  StereoFrame f;
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(cam.Capture(&f, 100).ok());
  const Status s = cam.Capture(&f, 10);
  EXPECT_EQ(s.code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(std::strstr(s.message(), "right camera silent"), nullptr) << s.message();
  const CameraStats st = cam.stats();
  EXPECT_EQ(st.timeouts, 1u);
  EXPECT_EQ(st.pairs_delivered, 3u);
  // The left frames produced meanwhile overflowed the left queue.
  EXPECT_EQ(st.left_overflow_drops, kSimFramesPerCapture - kStereoQueueDepth);
}

TEST(CameraSim, SilentSideIsReportedAndTheOtherSideCapturesAlone) {
  PatternSource source(8, 6);
  SimCameraConfig config;
  config.right_stop_after = 3;
  config.fault_starts = 1;  // the right camera is back after a restart
  SimCamera cam(&source, config);
  EXPECT_EQ(cam.SilentSide().status().code(), StatusCode::kNotFound) << "nothing captured yet";
  ASSERT_TRUE(cam.Start().ok());
  StereoFrame f;
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(cam.Capture(&f, 100).ok());
  ASSERT_EQ(cam.Capture(&f, 10).code(), StatusCode::kDeadlineExceeded);
  const Result<StereoSide> silent = cam.SilentSide();
  ASSERT_TRUE(silent.ok());
  EXPECT_EQ(*silent, StereoSide::kRight);

  // Left alone: every frame delivered, the right view empty, buffers recycled over many frames.
  ASSERT_TRUE(cam.Stop().ok());
  ASSERT_TRUE(cam.SetCaptureMode(CaptureMode::kLeftOnly).ok());
  EXPECT_EQ(cam.capture_mode(), CaptureMode::kLeftOnly);
  ASSERT_TRUE(cam.Start().ok());
  for (uint32_t i = 0; i < 3 * kSimBuffersPerSide; ++i) {
    ASSERT_TRUE(cam.Capture(&f, 100).ok()) << i;
    EXPECT_NE(f.left.data, nullptr);
    EXPECT_EQ(f.right.data, nullptr);
    EXPECT_EQ(f.left_sequence, i);
    EXPECT_EQ(f.left.at(1, 0), Pattern(i, 1, 0, false));
  }
  EXPECT_EQ(cam.stats().pairs_delivered, 3u * kSimBuffersPerSide);
  EXPECT_EQ(cam.stats().right_unpaired_drops, 0u);

  // Right alone.
  ASSERT_TRUE(cam.Stop().ok());
  ASSERT_TRUE(cam.SetCaptureMode(CaptureMode::kRightOnly).ok());
  ASSERT_TRUE(cam.Start().ok());
  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  EXPECT_EQ(f.left.data, nullptr);
  EXPECT_NE(f.right.data, nullptr);

  // Stereo again, with the right camera back (the fault applied to the first start only).
  ASSERT_TRUE(cam.Stop().ok());
  ASSERT_TRUE(cam.SetCaptureMode(CaptureMode::kStereo).ok());
  ASSERT_TRUE(cam.Start().ok());
  for (int i = 0; i < 6; ++i) ASSERT_TRUE(cam.Capture(&f, 100).ok()) << i;
  EXPECT_NE(f.left.data, nullptr);
  EXPECT_NE(f.right.data, nullptr);
}

TEST(CameraSim, BothCamerasStoppedTimesOut) {
  PatternSource source(8, 6);
  SimCameraConfig config;
  config.left_stop_after = 0;
  config.right_stop_after = 0;
  SimCamera cam(&source, config);
  ASSERT_TRUE(cam.Start().ok());
  StereoFrame f;
  const Status s = cam.Capture(&f, 5);
  EXPECT_EQ(s.code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(std::strstr(s.message(), "both cameras silent"), nullptr) << s.message();
}

TEST(CameraSim, AnAbsentCameraFailsTheStartOfEveryModeThatNeedsIt) {
  PatternSource source(8, 6);
  SimCameraConfig config;
  config.right_absent = true;
  SimCamera cam(&source, config);
  Status s = cam.Start();
  EXPECT_EQ(s.code(), StatusCode::kNotFound);
  EXPECT_NE(std::strstr(s.message(), "no right camera"), nullptr) << s.message();
  ASSERT_TRUE(cam.SetCaptureMode(CaptureMode::kRightOnly).ok());
  EXPECT_EQ(cam.Start().code(), StatusCode::kNotFound);
  ASSERT_TRUE(cam.SetCaptureMode(CaptureMode::kLeftOnly).ok());
  ASSERT_TRUE(cam.Start().ok());
  StereoFrame f;
  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  EXPECT_NE(f.left.data, nullptr);
  EXPECT_EQ(f.right.data, nullptr);
  cam.Release();
  ASSERT_TRUE(cam.Stop().ok());

  // Only in the first fault_starts starts: then the camera is plugged in.
  config.right_absent = false;
  config.left_absent = true;
  config.fault_starts = 1;
  SimCamera back(&source, config);
  ASSERT_TRUE(back.SetCaptureMode(CaptureMode::kRightOnly).ok());
  ASSERT_TRUE(back.Start().ok());  // start 1: the left camera is absent
  ASSERT_TRUE(back.Stop().ok());
  ASSERT_TRUE(back.SetCaptureMode(CaptureMode::kStereo).ok());
  ASSERT_TRUE(back.Start().ok());  // start 2: both there
  ASSERT_TRUE(back.Capture(&f, 100).ok());
  EXPECT_NE(f.left.data, nullptr);
  EXPECT_NE(f.right.data, nullptr);
}

TEST(CameraSim, DroppedLeftFramesLeaveRightFramesUnpaired) {
  PatternSource source(8, 6);
  SimCameraConfig config;
  config.drop_left_every = 3;  // frames 2, 5, 8, ... lose their left image
  SimCamera cam(&source, config);
  ASSERT_TRUE(cam.Start().ok());
  int64_t last = -1;
  for (int i = 0; i < 20; ++i) {
    StereoFrame f;
    ASSERT_TRUE(cam.Capture(&f, 100).ok());
    const int64_t n = FrameShown(f.left, false);
    EXPECT_EQ(FrameShown(f.right, true), n);
    EXPECT_NE(n % 3, 2) << "frame " << n << " should have lost its left image";
    EXPECT_GT(n, last);
    last = n;
  }
  const CameraStats s = cam.stats();
  // Frames 0..last were produced; every dropped left frame left one right frame without partner
  // (the last one may still be queued).
  const uint64_t dropped = static_cast<uint64_t>(last + 1) / 3;
  EXPECT_EQ(s.right_unpaired_drops, dropped);
  EXPECT_EQ(s.left_unpaired_drops, 0u);
}

// The pool holds a full side queue and the frame being rendered (kSimBuffersPerSide): with a
// silent side filling the other side's queue, drift, skew beyond the tolerance and drops, every
// frame finds a buffer (no frame dropped for want of one, no error), and the queues do fill.
TEST(CameraSim, PoolOfAFullQueueAndOneFrameNeverRunsDry) {
  std::vector<SimCameraConfig> configs(5);
  configs[0].right_stop_after = 3;
  configs[1].left_stop_after = 2;
  configs[2].right_drift_ppb = 1'000'000;
  configs[3].right_offset_ns = 10 * kMs;
  configs[4].jitter_ns = 1'500'000;
  configs[4].drop_left_every = 3;
  configs[4].drop_right_every = 5;
  uint64_t overflows = 0;
  for (size_t c = 0; c < configs.size(); ++c) {
    PatternSource source(8, 6);
    SimCamera cam(&source, configs[c]);
    ASSERT_TRUE(cam.Start().ok());
    for (int i = 0; i < 60; ++i) {
      StereoFrame f;
      const Status s = cam.Capture(&f, 1);
      EXPECT_TRUE(s.ok() || s.code() == StatusCode::kDeadlineExceeded) << c << ": " << s.message();
    }
    const CameraStats st = cam.stats();
    EXPECT_EQ(st.no_buffer_drops, 0u) << c;
    EXPECT_EQ(st.errors, 0u) << c;
    overflows += st.left_overflow_drops + st.right_overflow_drops;
  }
  EXPECT_GT(overflows, 0u) << "no side queue filled: the pool was never at its limit";
}

TEST(CameraSim, SkewWithinTolerancePairsAndBeyondToleranceTimesOut) {
  PatternSource source(8, 6);
  SimCameraConfig config;
  config.right_offset_ns = 1500'000;
  {
    SimCamera cam(&source, config);
    ASSERT_TRUE(cam.Start().ok());
    StereoFrame f;
    ASSERT_TRUE(cam.Capture(&f, 100).ok());
    EXPECT_EQ(f.right_timestamp_ns - f.left_timestamp_ns, config.right_offset_ns);
  }
  config.right_offset_ns = 10 * kMs;
  SimCamera cam(&source, config);
  ASSERT_TRUE(cam.Start().ok());
  StereoFrame f;
  const Status s = cam.Capture(&f, 5);
  EXPECT_EQ(s.code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(std::strstr(s.message(), "none within"), nullptr) << s.message();
  EXPECT_GT(cam.stats().left_unpaired_drops, 0u);
}

TEST(CameraSim, JitterWithinTolerancePairsEveryFrame) {
  PatternSource source(8, 6);
  SimCameraConfig config;
  config.jitter_ns = 900'000;  // two sides at most 1.8 ms apart < 2 ms tolerance
  config.jitter_seed = 77;
  SimCamera cam(&source, config);
  ASSERT_TRUE(cam.Start().ok());
  bool saw_difference = false;
  for (int i = 0; i < 100; ++i) {
    StereoFrame f;
    ASSERT_TRUE(cam.Capture(&f, 100).ok());
    EXPECT_EQ(FrameShown(f.left, false), i);
    const int64_t d = f.right_timestamp_ns - f.left_timestamp_ns;
    EXPECT_LE(std::llabs(d), config.pairing.tolerance_ns);
    saw_difference |= d != 0;
  }
  EXPECT_TRUE(saw_difference) << "jitter had no effect";
  EXPECT_EQ(cam.stats().left_unpaired_drops + cam.stats().right_unpaired_drops, 0u);
}

TEST(CameraSim, DriftEventuallyBreaksPairing) {
  PatternSource source(8, 6);
  SimCameraConfig config;
  config.right_drift_ppb = 1'000'000;  // 0.1 %: 33 us per frame, past 2 ms after ~60 frames
  SimCamera cam(&source, config);
  ASSERT_TRUE(cam.Start().ok());
  Status s;
  int delivered = 0;
  for (int i = 0; i < 200 && s.ok(); ++i) {
    StereoFrame f;
    s = cam.Capture(&f, 5);
    if (s.ok()) {
      EXPECT_LE(f.right_timestamp_ns - f.left_timestamp_ns, config.pairing.tolerance_ns);
      EXPECT_GE(f.right_timestamp_ns, f.left_timestamp_ns);
      ++delivered;
    }
  }
  EXPECT_EQ(s.code(), StatusCode::kDeadlineExceeded);
  EXPECT_GT(delivered, 0);
  EXPECT_GT(cam.stats().left_unpaired_drops, 0u);
}

TEST(CameraSim, SourceErrorIsReportedCountedAndSkipped) {
  PatternSource source(8, 6);
  source.fail_at = 2;
  SimCamera cam(&source, SimCameraConfig{});
  ASSERT_TRUE(cam.Start().ok());
  StereoFrame f;
  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  const Status bad = cam.Capture(&f, 100);
  EXPECT_EQ(bad.code(), StatusCode::kDataLoss);
  EXPECT_STREQ(bad.message(), "frame 2 is corrupt");
  EXPECT_EQ(cam.stats().errors, 1u);
  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  EXPECT_EQ(FrameShown(f.left, false), 3);
}

TEST(CameraSim, EndOfSourceIsReportedWithoutCountingAnError) {
  PatternSource source(8, 6);
  source.end_after = 2;
  SimCamera cam(&source, SimCameraConfig{});
  ASSERT_TRUE(cam.Start().ok());
  StereoFrame f;
  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  EXPECT_EQ(cam.Capture(&f, 100).code(), StatusCode::kOutOfRange);
  EXPECT_EQ(cam.Capture(&f, 100).code(), StatusCode::kOutOfRange);
  EXPECT_EQ(cam.stats().errors, 0u);
  EXPECT_EQ(source.renders, 3) << "an ended source is not asked again";
}

}  // namespace
}  // namespace sh::hal
