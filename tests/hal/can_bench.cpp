// Throughput of the CAN protocol encoder and the simulated bus (the per-result cost the firmware
// pays on the board, and the simulator's own overhead).
#include <benchmark/benchmark.h>

#include <cmath>

#include "firmware/plc/result_assembler.hpp"
#include "firmware/result_codec.hpp"
#include "hal/sim/can_sim_bus.hpp"

namespace {

using namespace sh;

protocol::ResultSet MakeSet(int objects) {
  protocol::ResultSet set;
  set.object_count = static_cast<uint8_t>(objects);
  for (int i = 0; i < objects; ++i) {
    protocol::ObjectPose& p = set.objects[i];
    p.model_id = static_cast<uint8_t>(i % 32);
    p.score = 0.9;
    p.cam_t_model_mm[0] = 10.0 * i;
    p.cam_t_model_mm[1] = -5.0 * i;
    p.cam_t_model_mm[2] = 800.0;
    const double half = 0.01 * i;
    p.cam_q_model[0] = std::cos(half);
    p.cam_q_model[3] = std::sin(half);
  }
  return set;
}

void BM_EncodeResultSet(benchmark::State& state) {
  const protocol::ResultSet set = MakeSet(static_cast<int>(state.range(0)));
  Vector<hal::CanFrame, protocol::kMaxResultFrames> frames;
  for (auto _ : state) {
    frames.clear();
    const Status s = protocol::EncodeResultSet(set, 1, frames);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(frames.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_EncodeResultSet)->Arg(1)->Arg(10)->Arg(64);

void BM_AssembleResultSet(benchmark::State& state) {
  const protocol::ResultSet set = MakeSet(static_cast<int>(state.range(0)));
  Vector<hal::CanFrame, protocol::kMaxResultFrames> frames;
  if (!protocol::EncodeResultSet(set, 1, frames).ok()) state.SkipWithError("encode failed");
  protocol::ResultAssembler assembler(1);
  for (auto _ : state) {
    for (const hal::CanFrame& f : frames) benchmark::DoNotOptimize(assembler.Feed(f));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_AssembleResultSet)->Arg(10);

void BM_SimBusSendReceive(benchmark::State& state) {
  static hal::SimCanBus bus;
  static hal::SimCanEndpoint* a = *bus.AddEndpoint({});
  static hal::SimCanEndpoint* b = *bus.AddEndpoint({});
  hal::CanFrame f;
  f.id = 0x181;
  f.len = 8;
  hal::CanFrame got;
  for (auto _ : state) {
    benchmark::DoNotOptimize(a->Send(f));
    benchmark::DoNotOptimize(b->Receive(&got, 0));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SimBusSendReceive);

}  // namespace

BENCHMARK_MAIN();
