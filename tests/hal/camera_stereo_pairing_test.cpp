#include "hal/stereo_pairing.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

namespace sh::hal {
namespace {

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kPeriodNs = 33 * kMs;
constexpr int64_t kToleranceNs = 2 * kMs;

TimestampedFrame Frame(int64_t t_ns, uint32_t seq) {
  TimestampedFrame f;
  f.timestamp_ns = t_ns;
  f.sequence = seq;
  f.buffer_id = seq;
  return f;
}

// Counts what the pairer hands back so that every pushed frame can be accounted for.
struct Harness {
  Harness() : Harness(PairingConfig{kToleranceNs}) {}
  explicit Harness(const PairingConfig& config) {
    EXPECT_TRUE(pairer.Configure(config).ok());
    RecycleList r;
    pairer.Reset(r);
  }
  void Push(StereoSide side, int64_t t_ns, uint32_t seq) {
    RecycleList r;
    pairer.Push(side, Frame(t_ns, seq), r);
    for (const RecycledFrame& f : r) ++recycled[static_cast<int>(f.side)];
    ++pushed[static_cast<int>(side)];
  }
  bool Take(FramePair* p) { return pairer.WaitPair(0, p).ok(); }
  void DrainAll() {
    RecycleList r;
    pairer.Drain(r);
    for (const RecycledFrame& f : r) ++recycled[static_cast<int>(f.side)];
  }
  StereoPairer pairer;
  uint64_t pushed[2] = {};
  uint64_t recycled[2] = {};
};

TEST(CameraStereoPairing, RejectsNegativeTolerance) {
  StereoPairer p;
  const Status s = p.Configure(PairingConfig{-1});
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::strstr(s.message(), "tolerance"), nullptr) << s.message();
}

TEST(CameraStereoPairing, WaitBeforeResetReportsNotStarted) {
  StereoPairer p;
  FramePair pair;
  EXPECT_EQ(p.WaitPair(0, &pair).code(), StatusCode::kFailedPrecondition);
}

TEST(CameraStereoPairing, PairsJitteredFramesWithinTolerance) {
  Harness h;
  // Deterministic jitter up to +-0.9 ms per side, so left-right differences stay within 1.8 ms;
  // the arrival order alternates as it does between two completion callbacks.
  uint32_t state = 12345;
  auto jitter = [&state]() {
    state = state * 1103515245u + 12345u;
    return static_cast<int64_t>((state >> 8) % 1'800'001) - 900'000;
  };
  constexpr int kFrames = 200;
  int delivered = 0;
  for (int i = 0; i < kFrames; ++i) {
    const int64_t t = i * kPeriodNs;
    const int64_t tl = t + jitter();
    const int64_t tr = t + jitter();
    if (i % 2 == 0) {
      h.Push(StereoSide::kLeft, tl, i);
      h.Push(StereoSide::kRight, tr, i);
    } else {
      h.Push(StereoSide::kRight, tr, i);
      h.Push(StereoSide::kLeft, tl, i);
    }
    FramePair p;
    ASSERT_TRUE(h.Take(&p)) << "frame " << i;
    EXPECT_EQ(p.left.sequence, p.right.sequence);
    EXPECT_LE(std::llabs(p.left.timestamp_ns - p.right.timestamp_ns), kToleranceNs);
    EXPECT_EQ(p.pair_index, static_cast<uint64_t>(delivered));
    ++delivered;
  }
  const CameraStats s = h.pairer.stats();
  EXPECT_EQ(s.frames_paired, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(s.pairs_delivered, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(s.left_unpaired_drops + s.right_unpaired_drops, 0u);
  EXPECT_EQ(h.recycled[0] + h.recycled[1], 0u);
}

TEST(CameraStereoPairing, RightCameraStoppedTimesOutNamingTheSilentSide) {
  Harness h;
  h.Push(StereoSide::kLeft, 0, 0);
  h.Push(StereoSide::kRight, 0, 0);
  FramePair p;
  ASSERT_TRUE(h.Take(&p));
  for (int i = 1; i <= 3; ++i) h.Push(StereoSide::kLeft, i * kPeriodNs, i);
  const Status s = h.pairer.WaitPair(5, &p);
  EXPECT_EQ(s.code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(std::strstr(s.message(), "right camera silent"), nullptr) << s.message();
  EXPECT_NE(std::strstr(s.message(), "left camera delivered 3"), nullptr) << s.message();
  EXPECT_EQ(h.pairer.stats().timeouts, 1u);
}

TEST(CameraStereoPairing, BothCamerasSilentSaysSo) {
  Harness h;
  FramePair p;
  const Status s = h.pairer.WaitPair(1, &p);
  EXPECT_EQ(s.code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(std::strstr(s.message(), "both cameras silent"), nullptr) << s.message();
}

TEST(CameraStereoPairing, StalledSideOverflowsDroppingOldestAndRecyclesEveryFrame) {
  Harness h;
  constexpr int kPushed = static_cast<int>(kStereoQueueDepth) + 5;
  for (int i = 0; i < kPushed; ++i) h.Push(StereoSide::kLeft, i * kPeriodNs, i);
  const CameraStats s = h.pairer.stats();
  EXPECT_EQ(s.left_overflow_drops, static_cast<uint64_t>(kPushed) - kStereoQueueDepth);
  EXPECT_EQ(h.recycled[0], s.left_overflow_drops);
  // The newest frames survived: a right frame matching the last left one pairs with it.
  h.Push(StereoSide::kRight, (kPushed - 1) * kPeriodNs + 500'000, 0);
  FramePair p;
  ASSERT_TRUE(h.Take(&p));
  EXPECT_EQ(p.left.sequence, static_cast<uint32_t>(kPushed - 1));
  // The older queued left frames were behind the right one by far more than the tolerance.
  EXPECT_EQ(h.pairer.stats().left_unpaired_drops, kStereoQueueDepth - 1);
  EXPECT_EQ(h.recycled[0] + 1, h.pushed[0]);
}

TEST(CameraStereoPairing, CameraRestartAfterStallResumesPairing) {
  Harness h;
  for (int i = 0; i < 3; ++i) h.Push(StereoSide::kLeft, i * kPeriodNs, i);
  // The right camera comes up a second later; the stale left frames are unpairable.
  const int64_t t0 = 1000 * kMs;
  for (int i = 0; i < 5; ++i) {
    h.Push(StereoSide::kRight, t0 + i * kPeriodNs + 300'000, 100 + i);
    h.Push(StereoSide::kLeft, t0 + i * kPeriodNs, 100 + i);
    FramePair p;
    ASSERT_TRUE(h.Take(&p)) << i;
    EXPECT_EQ(p.left.sequence, p.right.sequence);
  }
  EXPECT_EQ(h.pairer.stats().left_unpaired_drops, 3u);
  EXPECT_EQ(h.pairer.stats().right_unpaired_drops, 0u);
}

TEST(CameraStereoPairing, DriftBeyondToleranceDropsFramesButNeverPairsFarApart) {
  Harness h;
  // Right clock 0.5 % fast: the offset grows by ~0.17 ms per frame and passes the tolerance
  // after about 12 frames, then reaches half a period and locks onto the next left frame.
  constexpr int kFrames = 300;
  uint64_t delivered = 0;
  for (int i = 0; i < kFrames; ++i) {
    const int64_t t = i * kPeriodNs;
    h.Push(StereoSide::kLeft, t, i);
    h.Push(StereoSide::kRight, t + t / 200, i);
    FramePair p;
    while (h.Take(&p)) {
      EXPECT_LE(std::llabs(p.left.timestamp_ns - p.right.timestamp_ns), kToleranceNs);
      ++delivered;
    }
  }
  const CameraStats s = h.pairer.stats();
  EXPECT_GT(s.left_unpaired_drops + s.right_unpaired_drops, 0u);
  EXPECT_GT(delivered, 0u);
  EXPECT_LT(delivered, static_cast<uint64_t>(kFrames));
  // Every frame handed back so far was counted as a drop.
  EXPECT_EQ(h.recycled[0], s.left_unpaired_drops + s.left_overflow_drops);
  EXPECT_EQ(h.recycled[1], s.right_unpaired_drops + s.right_overflow_drops);
  // With the queues drained, every frame was either delivered or handed back exactly once.
  h.DrainAll();
  EXPECT_EQ(h.recycled[0] + delivered, h.pushed[0]);
  EXPECT_EQ(h.recycled[1] + delivered, h.pushed[1]);
}

TEST(CameraStereoPairing, ConstantSkewBeyondToleranceTimesOutWithDriftHint) {
  Harness h;
  for (int i = 0; i < 3; ++i) {
    h.Push(StereoSide::kLeft, i * kPeriodNs, i);
    h.Push(StereoSide::kRight, i * kPeriodNs + 10 * kMs, i);
  }
  FramePair p;
  const Status s = h.pairer.WaitPair(1, &p);
  EXPECT_EQ(s.code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(std::strstr(s.message(), "none within 2000 us"), nullptr) << s.message();
  EXPECT_EQ(h.pairer.stats().frames_paired, 0u);
}

TEST(CameraStereoPairing, SlowConsumerLosesOldestPairs) {
  Harness h;
  static_assert(kStereoQueueDepth > kStereoPairDepth, "test needs a burst longer than pair depth");
  // A burst as long as the side queues: every frame finds its partner, but the consumer does
  // not look until all pairs are formed.
  constexpr int kPairs = static_cast<int>(kStereoQueueDepth);
  for (int i = 0; i < kPairs; ++i) h.Push(StereoSide::kLeft, i * kPeriodNs, i);
  for (int i = 0; i < kPairs; ++i) h.Push(StereoSide::kRight, i * kPeriodNs + 100'000, i);
  const CameraStats s = h.pairer.stats();
  EXPECT_EQ(s.pair_overflow_drops, static_cast<uint64_t>(kPairs) - kStereoPairDepth);
  FramePair p;
  for (size_t k = 0; k < kStereoPairDepth; ++k) {
    ASSERT_TRUE(h.Take(&p));
    EXPECT_EQ(p.left.sequence, static_cast<uint32_t>(kPairs - kStereoPairDepth + k));
    EXPECT_EQ(p.pair_index, k);
  }
  EXPECT_FALSE(h.Take(&p));
  EXPECT_EQ(h.recycled[0], s.pair_overflow_drops);
  EXPECT_EQ(h.recycled[1], s.pair_overflow_drops);
}

TEST(CameraStereoPairing, OneSideModeDeliversEachFrameAloneAndHandsTheOtherSideBack) {
  Harness h;
  h.pairer.SetMode(CaptureMode::kRightOnly);
  EXPECT_EQ(h.pairer.SilentSide().status().code(), StatusCode::kNotFound);
  h.DrainAll();
  {
    RecycleList r;
    h.pairer.Reset(r);  // the mode applies from here
  }
  // Right frames alone; left frames (if the camera still sent any) go straight back.
  constexpr int kFrames = static_cast<int>(kStereoPairDepth) + 3;
  for (int i = 0; i < kFrames; ++i) {
    h.Push(StereoSide::kLeft, i * kPeriodNs, i);
    h.Push(StereoSide::kRight, i * kPeriodNs + 5 * kMs, i);  // far outside the tolerance
  }
  EXPECT_EQ(h.recycled[0], static_cast<uint64_t>(kFrames));
  const CameraStats s = h.pairer.stats();
  EXPECT_EQ(s.frames_paired, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(s.pair_overflow_drops, static_cast<uint64_t>(kFrames) - kStereoPairDepth);
  EXPECT_EQ(s.left_unpaired_drops + s.right_unpaired_drops, 0u);
  EXPECT_EQ(h.recycled[1], s.pair_overflow_drops) << "only the right half of dropped pairs";
  FramePair p;
  for (size_t k = 0; k < kStereoPairDepth; ++k) {
    ASSERT_TRUE(h.Take(&p));
    EXPECT_EQ(p.right.sequence, static_cast<uint32_t>(kFrames - kStereoPairDepth + k));
    EXPECT_EQ(p.left.timestamp_ns, 0);
  }
  EXPECT_FALSE(h.Take(&p));
  h.DrainAll();
  EXPECT_EQ(h.recycled[0] + h.recycled[1] + kStereoPairDepth, h.pushed[0] + h.pushed[1]);
}

TEST(CameraStereoPairing, SilentSideNamesTheSideWithoutFrames) {
  Harness h;
  h.Push(StereoSide::kLeft, 0, 0);
  h.Push(StereoSide::kRight, 0, 0);
  FramePair p;
  ASSERT_TRUE(h.Take(&p));
  EXPECT_EQ(h.pairer.SilentSide().status().code(), StatusCode::kNotFound) << "both delivered";
  h.Push(StereoSide::kLeft, kPeriodNs, 1);
  h.Push(StereoSide::kLeft, 2 * kPeriodNs, 2);
  const Result<StereoSide> silent = h.pairer.SilentSide();
  ASSERT_TRUE(silent.ok());
  EXPECT_EQ(*silent, StereoSide::kRight);
}

TEST(CameraStereoPairing, BurstOnOneSidePairsEachFrameWithItsPartner) {
  Harness h;
  // Right delivers three frames late in a burst after the left ones; kStereoQueueDepth >= 3.
  for (int i = 0; i < 3; ++i) h.Push(StereoSide::kLeft, i * kPeriodNs, i);
  for (int i = 0; i < 3; ++i) h.Push(StereoSide::kRight, i * kPeriodNs - 700'000, i);
  FramePair p;
  ASSERT_TRUE(h.Take(&p));
  // One pair was lost to the pair queue depth only if that depth is below 3.
  const uint64_t lost = h.pairer.stats().pair_overflow_drops;
  EXPECT_EQ(lost, kStereoPairDepth >= 3 ? 0u : 3 - kStereoPairDepth);
  EXPECT_EQ(p.left.sequence, p.right.sequence);
  EXPECT_EQ(h.pairer.stats().left_unpaired_drops + h.pairer.stats().right_unpaired_drops, 0u);
}

TEST(CameraStereoPairing, PrefersTheCloserOfTwoQueuedPartners) {
  Harness h(PairingConfig{5 * kMs});
  h.Push(StereoSide::kRight, 0, 1);
  h.Push(StereoSide::kRight, 4 * kMs, 2);
  h.Push(StereoSide::kLeft, 3'500'000, 7);
  FramePair p;
  ASSERT_TRUE(h.Take(&p));
  EXPECT_EQ(p.right.sequence, 2u);
  EXPECT_EQ(h.pairer.stats().right_unpaired_drops, 1u);
}

TEST(CameraStereoPairing, TimestampGoingBackwardsIsAnErrorAndHandedBack) {
  Harness h;
  h.Push(StereoSide::kLeft, 10 * kMs, 0);
  h.Push(StereoSide::kLeft, 5 * kMs, 1);
  h.Push(StereoSide::kLeft, 10 * kMs, 2);
  EXPECT_EQ(h.pairer.stats().errors, 2u);
  EXPECT_EQ(h.recycled[0], 2u);
}

TEST(CameraStereoPairing, CloseWakesWaitingConsumerWithReason) {
  Harness h;
  std::atomic<bool> done{false};
  Status result;
  std::thread consumer([&] {
    FramePair p;
    result = h.pairer.WaitPair(60'000, &p);
    done = true;
  });
  h.pairer.Close(Status::Error(StatusCode::kUnavailable, "left camera disconnected"));
  consumer.join();
  EXPECT_TRUE(done);
  EXPECT_EQ(result.code(), StatusCode::kUnavailable);
  EXPECT_STREQ(result.message(), "left camera disconnected");
  // Frames pushed after closing go straight back.
  h.Push(StereoSide::kLeft, 0, 0);
  EXPECT_EQ(h.recycled[0], 1u);
}

TEST(CameraStereoPairing, QueuedPairsAreStillDeliveredAfterClose) {
  Harness h;
  h.Push(StereoSide::kLeft, 0, 0);
  h.Push(StereoSide::kRight, 0, 0);
  h.pairer.Close(Status::Error(StatusCode::kUnavailable, "stopped"));
  FramePair p;
  EXPECT_TRUE(h.pairer.WaitPair(0, &p).ok());
  EXPECT_EQ(h.pairer.WaitPair(0, &p).code(), StatusCode::kUnavailable);
}

TEST(CameraStereoPairing, NegativeTimeoutIsRejected) {
  Harness h;
  FramePair p;
  EXPECT_EQ(h.pairer.WaitPair(-1, &p).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(h.pairer.WaitPair(0, nullptr).code(), StatusCode::kInvalidArgument);
}

// Two producer threads (like two libcamera completion callbacks) and one consumer: every frame is
// delivered or handed back exactly once, and no delivered pair is out of tolerance or order.
TEST(CameraStereoPairing, ConcurrentProducersAndConsumerAccountForEveryFrame) {
  Harness h;
  constexpr int kFrames = 5000;
  std::atomic<uint64_t> recycled[2] = {{0}, {0}};
  std::atomic<bool> producers_done{false};
  auto produce = [&](StereoSide side, int64_t offset_ns) {
    for (int i = 0; i < kFrames; ++i) {
      RecycleList r;
      h.pairer.Push(side, Frame(i * kPeriodNs + offset_ns + (i % 3) * 200'000, i), r);
      for (const RecycledFrame& f : r) ++recycled[static_cast<int>(f.side)];
      if (i % 64 == 0) std::this_thread::yield();
    }
  };
  std::vector<FramePair> pairs;
  pairs.reserve(kFrames);
  std::thread consumer([&] {
    FramePair p;
    for (;;) {
      // Read before waiting: a wait that times out after the producers finished has seen every
      // pair. Reading it after the wait would miss pairs formed between the timeout and the read.
      const bool producers_were_done = producers_done;
      const Status s = h.pairer.WaitPair(20, &p);
      if (s.ok()) {
        pairs.push_back(p);
      } else if (producers_were_done) {
        return;
      }
    }
  });
  std::thread left(produce, StereoSide::kLeft, 0);
  std::thread right(produce, StereoSide::kRight, 700'000);
  left.join();
  right.join();
  producers_done = true;
  consumer.join();
  RecycleList rest;
  h.pairer.Drain(rest);
  for (const RecycledFrame& f : rest) ++recycled[static_cast<int>(f.side)];

  for (size_t i = 0; i < pairs.size(); ++i) {
    EXPECT_LE(std::llabs(pairs[i].left.timestamp_ns - pairs[i].right.timestamp_ns), kToleranceNs);
    EXPECT_EQ(pairs[i].left.sequence, pairs[i].right.sequence);
    if (i > 0) {
      EXPECT_GT(pairs[i].left.sequence, pairs[i - 1].left.sequence);
    }
  }
  EXPECT_EQ(recycled[0] + pairs.size(), static_cast<uint64_t>(kFrames));
  EXPECT_EQ(recycled[1] + pairs.size(), static_cast<uint64_t>(kFrames));
  const CameraStats s = h.pairer.stats();
  EXPECT_EQ(s.pairs_delivered, pairs.size());
  EXPECT_EQ(s.frames_paired, s.pairs_delivered + s.pair_overflow_drops);
  EXPECT_GT(pairs.size(), 0u);
}

}  // namespace
}  // namespace sh::hal
