// Build-time generator of the linked-in default tables: tablegen <models dir> <hash fn> <out>,
// the models in the order of the folder's manifest (tables/model_files.hpp).
#include <cstdio>
#include <cstdlib>

#include "tables/model_files.hpp"
#include "tools/tablegen/table_builder.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s <models dir> <hash fn 1..5> <out.bin>\n", argv[0]);
    return 2;
  }
  std::vector<sh::Model> models;
  const sh::Status loaded = sh::LoadModelFolder(argv[1], &models);
  if (!loaded.ok()) {
    std::fprintf(stderr, "tablegen: %s\n", loaded.message());
    return 1;
  }
  sh::TableBuildOptions options;
  const int hf = std::atoi(argv[2]);
  if (!sh::IsValidHashFunction(hf)) {
    std::fprintf(stderr, "tablegen: hash function must be 1..5\n");
    return 2;
  }
  options.hash_function = static_cast<sh::HashFunction>(hf);
  auto blob = sh::BuildTableBlob(models, options);
  if (!blob.ok()) {
    std::fprintf(stderr, "tablegen: %s\n", blob.status().message());
    return 1;
  }
  FILE* out = std::fopen(argv[3], "wb");
  if (out == nullptr || std::fwrite(blob->data(), 1, blob->size(), out) != blob->size() ||
      std::fclose(out) != 0) {
    std::fprintf(stderr, "tablegen: cannot write %s\n", argv[3]);
    return 1;
  }
  return 0;
}
