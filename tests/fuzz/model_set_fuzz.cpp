// Fuzzes the model-set container reader: any byte string must be refused with a Status or
// opened into a view whose every section lies inside the blob, where the kinds' own views then
// open (or refuse) their sections.
#include <cstdint>
#include <cstring>
#include <vector>

#include "tables/aspect_view.hpp"
#include "tables/model_set.hpp"
#include "tables/table_view.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The reader requires 8-byte alignment, as mmap and the linked-in data give.
  static std::vector<uint64_t> storage;
  storage.assign(size / 8 + 1, 0);
  std::memcpy(storage.data(), data, size);
  auto* bytes = reinterpret_cast<uint8_t*>(storage.data());
  // Mutations almost never keep the CRCs right; for half of the inputs (by the last byte) fix
  // the whole-blob CRC up, so that the directory checks behind it get fuzzed too.
  if (size > sizeof(sh::ModelSetHeader) && (data[size - 1] & 1)) {
    auto* header = reinterpret_cast<sh::ModelSetHeader*>(bytes);
    header->blob_crc32 = sh::ModelSetCrc32(bytes, size);
  }
  auto set = sh::ModelSetView::Open(bytes, size);
  if (!set.ok()) return 0;
  uint64_t sum = 0;
  for (uint32_t i = 0; i < set->section_count(); ++i) {
    const sh::BlobSpan p = set->payload(i);
    const auto* first = static_cast<const uint8_t*>(p.data);
    if (first < bytes || first + p.size > bytes + size) __builtin_trap();
    sum += first[0] + first[p.size - 1];
  }
  if (auto hash = set->FindSection(sh::SectionKind::kHash3d); hash.ok()) {
    auto view = sh::TableView::Open(hash->data, hash->size);
    if (view.ok()) sum += view->model_count();
  }
  if (auto aspects = set->FindSection(sh::SectionKind::kAspects2d); aspects.ok()) {
    auto view = sh::AspectTableView::Open(aspects->data, aspects->size);
    if (view.ok()) sum += view->model_count();
  }
  return sum == 0xdeadbeef ? 1 : 0;
}
