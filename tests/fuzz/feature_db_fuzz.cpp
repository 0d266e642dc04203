// Fuzzes the feature database loader: any byte string must be refused with a Status or opened
// into a view whose every accessor, and a kd-tree search over it, stays inside the blob.
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "recog/base/crc32.hpp"
#include "recog/image/image.hpp"
#include "recog/texture/kd_tree.hpp"
#include "tables/feature_db_view.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The loader requires 16-byte alignment, as mmap and linked-in data give.
  static std::vector<uint64_t> storage;
  storage.assign(size / 8 + 2, 0);
  auto* bytes = reinterpret_cast<uint8_t*>(storage.data());
  bytes += reinterpret_cast<uintptr_t>(bytes) % 16;
  std::memcpy(bytes, data, size);
  // Mutations almost never keep the CRC right; for half of the inputs (by the last byte) fix it
  // up so that the structural checks behind the CRC get fuzzed too.
  if (size > sizeof(sh::FeatureDbHeader) && (data[size - 1] & 1)) {
    auto* header = reinterpret_cast<sh::FeatureDbHeader*>(bytes);
    header->blob_crc32 = sh::BlobCrc32(bytes, size, offsetof(sh::FeatureDbHeader, blob_crc32));
  }
  auto view = sh::FeatureDbView::Open(bytes, size);
  if (!view.ok()) return 0;
  uint64_t sum = 0;
  for (uint32_t i = 0; i < view->feature_count(); ++i) {
    const sh::FeatureRecord& f = view->feature(i);
    const sh::TexturedFace& face = view->face(view->view(f.view).face);
    sum += view->model(face.model).faces[face.model_face].n_vertices + view->descriptor(i).v[7];
  }
  for (uint32_t i = 0; i < view->face_count(); ++i) {
    const sh::FaceTexels texels = view->face_texels(i);
    const sh::ConstGrayView t{texels.texels, texels.width, texels.height, texels.width};
    sum += t.at(t.width - 1, t.height - 1);
  }
  static auto searcher = std::make_unique<sh::texture::KdSearcher>();
  sh::texture::TextureDescriptor query;
  for (int k = 0; k < sh::texture::kDescriptorSize; ++k) query.v[k] = data[k % size];
  sh::texture::KdNeighbour out[4];
  const int n = searcher->Search(view->tree(), query, 4, 64, out);
  for (int i = 0; i < n; ++i) sum += view->feature(out[i].index).view;
  return sum == 0xdeadbeef ? 1 : 0;
}
