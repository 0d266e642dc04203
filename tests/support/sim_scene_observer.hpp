// For the firmware tests over the simulated world: which rendered scene each result set showed
// (and in what pixel format its frames came), and writing the data files a test boots from.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <thread>

#include "firmware/firmware_core.hpp"
#include "hal/sim/world/sim_world.hpp"
#include "tests/support/test_files.hpp"

namespace sh::testing {

// The scene of each result set, by its sequence (the core reports a set after sending it).
class SceneObserver final : public fw::CoreObserver {
 public:
  explicit SceneObserver(const render::SimWorld* world) : world_(world) {}
  void OnResult(const protocol::ResultSet& set, const hal::StereoFrame* frame) override {
    if (frame == nullptr) return;
    colour_frames_ += frame->left_frame.has_colour() ? 1 : 0;
    scene_ = world_->SceneOfFrame(frame->left_sequence);
    sequence_ = set.sequence;
    ++results_;
  }
  // The scene of the set with this sequence, waiting for the report (-1: none came).
  int SceneOf(uint16_t sequence) const {
    for (int i = 0; i < 5000; ++i) {
      if (results_.load() > 0 && sequence_.load() == sequence) return scene_.load();
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return -1;
  }
  // Result sets whose left frame was in a colour format.
  int colour_frames() const { return colour_frames_.load(); }

 private:
  const render::SimWorld* world_;
  std::atomic<int> scene_{-1};
  std::atomic<uint16_t> sequence_{0};
  std::atomic<int> results_{0};
  std::atomic<int> colour_frames_{0};
};

}  // namespace sh::testing
