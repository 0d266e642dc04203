// Fuzzes the aspect table loader: any byte string must be refused with a Status or opened into
// a view whose every accessor stays inside the blob, and a vote over it must stay inside too.
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "recog/base/crc32.hpp"
#include "recog/mono/aspect_voter.hpp"
#include "tables/aspect_view.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The loader requires 8-byte alignment, as mmap and the linked-in tables give.
  static std::vector<uint64_t> storage;
  static auto* voter = new sh::AspectVoter;  // large: allocated once
  storage.assign(size / 8 + 1, 0);
  std::memcpy(storage.data(), data, size);
  // Mutations almost never keep the CRC right; for half of the inputs (by the last byte) fix it
  // up so that the structural checks behind the CRC get fuzzed too.
  if (size > sizeof(sh::AspectHeader) && (data[size - 1] & 1)) {
    auto* header = reinterpret_cast<sh::AspectHeader*>(storage.data());
    header->blob_crc32 =
        sh::BlobCrc32(storage.data(), size, offsetof(sh::AspectHeader, blob_crc32));
  }
  auto view = sh::AspectTableView::Open(storage.data(), size);
  if (!view.ok()) return 0;
  uint64_t sum = 0;
  for (uint32_t b = 0; b < view->basis_count(); ++b) {
    const sh::AspectBasis& basis = view->basis(b);
    sum += view->aspect(basis.aspect).n_corners + view->model(basis.model).n_corners;
  }
  // A small scene voted against the table: bins, entries and bases are read through the
  // offsets the loader checked.
  if (voter->Init(*view, sh::VoterConfig{}).ok()) {
    sh::ScenePoint2d points[4] = {{{0, 0}}, {{60, 0}}, {{30, 40}}, {{10, -30}}};
    sh::SceneLine2d lines[2];
    lines[0].point = {0, 0};
    lines[0].dir = {1, 0};
    lines[0].t1 = 60;
    lines[1].point = {60, 0};
    lines[1].dir = {0, 1};
    lines[1].t1 = 50;
    sh::VoteScene scene;
    scene.points = points;
    scene.n_points = 4;
    scene.lines = lines;
    scene.n_lines = 2;
    sh::VoteRequest request;
    request.frame = sh::SimilarityFrame(points[0].xy, points[1].xy);
    request.exclude[0] = 0;
    request.exclude[1] = 1;
    request.n_exclude = 2;
    sh::AspectHypothesis out[4];
    sum += static_cast<uint64_t>(voter->Vote(scene, request, out, 4));
  }
  return sum == 0xdeadbeef ? 1 : 0;
}
