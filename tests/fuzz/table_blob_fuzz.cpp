// Fuzzes the table blob loader: any byte string must be refused with a Status or opened into a
// view whose every accessor stays inside the blob.
#include <cstdint>
#include <cstring>
#include <vector>

#include "tables/table_view.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The loader requires 8-byte alignment, as mmap and the linked-in tables give.
  static std::vector<uint64_t> storage;
  storage.assign(size / 8 + 1, 0);
  std::memcpy(storage.data(), data, size);
  // Mutations almost never keep the CRC right; for half of the inputs (by the last byte) fix it
  // up so that the structural checks behind the CRC get fuzzed too.
  if (size > sizeof(sh::TableHeader) && (data[size - 1] & 1)) {
    auto* header = reinterpret_cast<sh::TableHeader*>(storage.data());
    header->blob_crc32 = sh::TableBlobCrc32(reinterpret_cast<const uint8_t*>(storage.data()), size);
  }
  auto view = sh::TableView::Open(storage.data(), size);
  if (!view.ok()) return 0;
  uint64_t sum = 0;
  for (uint32_t bin = 0; bin < view->point_grid().bin_count(); ++bin)
    for (const sh::PointEntry& e : view->point_bin(bin)) sum += uint64_t(e.basis) + uint16_t(e.x);
  for (uint32_t bin = 0; bin < view->line_grid().bin_count(); ++bin)
    for (const sh::LineEntry& e : view->line_bin(bin)) sum += view->basis(e.basis).model + e.length;
  for (uint32_t m = 0; m < view->model_count(); ++m) {
    const sh::Model& model = view->model(m);
    for (int e = 0; e < model.n_edges; ++e) sum += model.faces[model.edges[e].face0].n_vertices;
  }
  return sum == 0xdeadbeef ? 1 : 0;
}
