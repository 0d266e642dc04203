// Fuzzes the view database loader: any byte string must be refused with a Status or opened into
// a view whose models, views, coefficients and search stay inside the blob.
#include <cstdint>
#include <cstring>
#include <vector>

#include "recog/base/crc32.hpp"
#include "recog/shape/view_database.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The loader requires 8-byte alignment, as mmap gives.
  static std::vector<uint64_t> storage;
  storage.assign(size / 8 + 1, 0);
  std::memcpy(storage.data(), data, size);
  // For half of the inputs (by the last byte) fix the CRC up so that the structural checks
  // behind it get fuzzed too.
  if (size > sizeof(sh::ShapeViewsHeader) && (data[size - 1] & 1)) {
    auto* header = reinterpret_cast<sh::ShapeViewsHeader*>(storage.data());
    header->blob_crc32 =
        sh::BlobCrc32(storage.data(), size, offsetof(sh::ShapeViewsHeader, blob_crc32));
  }
  auto view = sh::ShapeViewsView::Open(storage.data(), size);
  if (!view.ok()) return 0;
  uint64_t sum = 0;
  for (uint32_t m = 0; m < view->model_count(); ++m) {
    const sh::Model& model = view->model(m);
    for (int e = 0; e < model.n_edges; ++e) sum += model.faces[model.edges[e].face0].n_vertices;
    sum += view->shape_model(m).n_views;
  }
  for (uint32_t v = 0; v < view->view_count(); ++v) {
    sum += view->view(v).model + static_cast<uint16_t>(view->coefficients(v)[0]);
    sum += view->ViewRotation(v)(0, 0) > 0.5f;
  }
  // A window of constant energy: projection and search read every basis and view entry.
  static sh::ShapeWindow window;
  for (float& x : window.v) x = 1.0f / sh::kWindowSide;
  sh::ShapeCoefficients c;
  ProjectWindow(*view, window, &c);
  sh::Vector<sh::ViewMatch, 4> best;
  NearestViews(*view, c, 0xffffffffu, 4, best);
  for (const sh::ViewMatch& m : best) sum += m.view;
  return sum == 0xdeadbeef ? 1 : 0;
}
