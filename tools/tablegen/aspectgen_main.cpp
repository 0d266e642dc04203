// Build-time generator of the linked-in default aspect table: aspectgen <models dir> <out>.
#include <cstdio>

#include "tables/model_files.hpp"
#include "tools/tablegen/aspect_builder.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <models dir> <out.bin>\n", argv[0]);
    return 2;
  }
  std::vector<sh::Model> models;
  const sh::Status loaded = sh::LoadModelFolder(argv[1], &models);
  if (!loaded.ok()) {
    std::fprintf(stderr, "aspectgen: %s\n", loaded.message());
    return 1;
  }
  auto blob = sh::BuildAspectBlob(models, sh::AspectBuildOptions{});
  if (!blob.ok()) {
    std::fprintf(stderr, "aspectgen: %s\n", blob.status().message());
    return 1;
  }
  FILE* out = std::fopen(argv[2], "wb");
  if (out == nullptr || std::fwrite(blob->data(), 1, blob->size(), out) != blob->size() ||
      std::fclose(out) != 0) {
    std::fprintf(stderr, "aspectgen: cannot write %s\n", argv[2]);
    return 1;
  }
  return 0;
}
