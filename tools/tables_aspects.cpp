#include "tools/tables_aspects.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "recog/base/printable.hpp"
#include "tables/aspect_file.hpp"
#include "tables/model_files.hpp"
#include "tools/command.hpp"
#include "tools/tablegen/aspect_builder.hpp"

namespace sh::tools {
namespace {

// Thesis table 6.1 (similarity, relaxed grid check): aspect models and model bases per model.
struct ThesisModelRow {
  const char* model;
  uint32_t aspects, bases;
};
constexpr ThesisModelRow kThesisModels[] = {{"cube", 40, 1423},     {"hexagon", 35, 2503},
                                            {"wedge", 40, 794},     {"star", 10, 1212},
                                            {"pentagon", 39, 2000}, {"trapezium", 24, 834}};
// Thesis table 6.2: 2-D hash entries (similarity) and the largest bin.
constexpr uint32_t kThesisPointEntries = 60720, kThesisPointMaxBin = 142;
constexpr uint32_t kThesisLineEntries = 100182, kThesisLineMaxBin = 4722;

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

void DescribeAspects(const AspectTableView& v, size_t size) {
  const AspectHeader& h = v.header();
  std::printf(
      "aspect table, %s bases%s, format version %u, %zu bytes, CRC-32 %08x\n",
      v.basis_kind() == AspectBasisKind::kSimilarity ? "similarity (2-point)" : "affine (3-point)",
      (h.build.flags & kAspectEdgeBasesOnly) ? " over corners joined by edges" : "",
      h.format_version, size, h.blob_crc32);
  std::printf(
      "  %u models, %u aspects, %u model bases, %u point entries (largest bin %u), %u line "
      "entries (largest bin %u)\n",
      h.n_models, h.n_aspects, h.n_bases, h.n_point_entries, h.max_point_bin_entries,
      h.n_line_entries, h.max_line_bin_entries);
  std::printf(
      "  built with a %.0f-degree grid, up to %u refinements, test votes %.0f / %.0f px at "
      "%.0f px radius\n",
      double(h.build.initial_spacing_deg), h.build.max_levels, double(h.build.test_sigma_point_px),
      double(h.build.test_sigma_line_px), double(h.build.test_scale_px));
  std::vector<uint32_t> aspects(v.model_count()), bases(v.model_count());
  for (uint32_t a = 0; a < v.aspect_count(); ++a) {
    ++aspects[v.aspect(a).model];
    bases[v.aspect(a).model] += v.aspect(a).n_bases;
  }
  for (uint32_t m = 0; m < v.model_count(); ++m) {
    char shown[kPrintableNameBytes];  // names come from the blob: no raw control bytes
    std::printf("  model %u %-10s %4u aspects %6u bases\n", m,
                Printable(v.model(m).name, sizeof(Model::name), shown, sizeof(shown)), aspects[m],
                bases[m]);
  }
}

const char kAspectOptionsHelp[] =
    "  --hash-2d similarity|affine  the bases of the aspect table (ASPECTS_2D, written for\n"
    "                polyhedra unless --no-hash-2d):\n"
    "                aspect models of the polyhedra over a tessellated viewing sphere, refined\n"
    "                where test views fail, hashed with 2-point (similarity) or 3-point (affine)\n"
    "                bases over corners joined by edges (--all-pairs: over all corner pairs or\n"
    "                triples, as the thesis). --spacing DEG: initial grid (default 10);\n"
    "                --levels N: refinements (default 3; 0: none); --slices DIRECTIONS,SIZES:\n"
    "                line bins per direction and size (default 18,6).\n";

int ParseAspectOption(int argc, char** argv, int* i, AspectBuildOptions* options, bool* wanted) {
  const std::string a = argv[*i];
  const bool has_value = *i + 1 < argc;
  if (a == "--all-pairs") {
    options->edge_bases_only = false;
    return 1;
  }
  if (a != "--hash-2d" && a != "--slices" && a != "--spacing" && a != "--levels") return 0;
  if (!has_value) {
    std::fprintf(stderr, "stereohash tables build: %s needs a value\n", a.c_str());
    return -1;
  }
  const char* value = argv[++*i];
  if (a == "--hash-2d") {
    if (std::strcmp(value, "similarity") == 0) {
      options->kind = AspectBasisKind::kSimilarity;
    } else if (std::strcmp(value, "affine") == 0) {
      options->kind = AspectBasisKind::kAffine;
    } else {
      std::fprintf(stderr, "stereohash tables build: --hash-2d is similarity or affine\n");
      return -1;
    }
    *wanted = true;
  } else if (a == "--slices") {
    if (std::sscanf(value, "%d,%d", &options->line_angle_slices, &options->size_slices) != 2) {
      std::fprintf(stderr, "stereohash tables build: --slices needs DIRECTIONS,SIZES\n");
      return -1;
    }
  } else if (a == "--spacing") {
    double deg = 0;
    if (!OptionNumber("tables build", "--spacing", value, 0.1, 180, &deg)) return -1;
    options->initial_spacing_deg = static_cast<float>(deg);
  } else {
    long levels = 0;
    if (!OptionInteger("tables build", "--levels", value, 0, 100, &levels)) return -1;
    options->max_levels = int(levels);
    options->refine = options->max_levels > 0;
  }
  return 1;
}

Result<std::vector<uint8_t>> BuildAspectSection(const std::vector<Model>& models,
                                                const AspectBuildOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  AspectBuildReport report;
  Result<std::vector<uint8_t>> blob = BuildAspectBlob(models, options, &report);
  if (!blob.ok()) return blob.status();  // the builder's messages name the aspect table
  std::printf(
      "  ASPECTS_2D: %s aspect table, %zu bytes, %u aspects, %u bases, %u point and %u line "
      "entries (%.1f s)\n",
      options.kind == AspectBasisKind::kSimilarity ? "similarity" : "affine", blob->size(),
      report.aspects, report.bases, report.point_entries, report.line_entries, Seconds(start));
  return blob;
}

int CompareAspectsWithThesis(const std::string& models_dir) {
  std::vector<Model> models;
  const Status loaded = LoadModelFolder(models_dir, &models);
  if (!loaded.ok()) {
    std::fprintf(stderr, "stereohash tables info: %s\n", loaded.message());
    return 1;
  }
  struct Variant {
    const char* name;
    AspectBasisKind kind;
    bool edges_only;
    float spacing_deg;
  } variants[] = {
      {"similarity, all corner pairs, 15 deg (thesis)", AspectBasisKind::kSimilarity, false, 15},
      {"similarity, pairs joined by edges (default)", AspectBasisKind::kSimilarity, true, 10},
      {"affine, two edges at a corner", AspectBasisKind::kAffine, true, 10}};
  std::printf(
      "\n2-D aspect tables of the six reference models beside the thesis (tables 6.1, 6.2; the "
      "thesis's\ncounts are for similarity bases over all corner pairs).\n\n");
  std::printf("%-46s | %8s | %-18s | %-17s | %-18s | %-17s\n", "tables", "aspects", "point entries",
              "largest point bin", "line entries", "largest line bin");
  AspectBuildReport similarity_all;
  for (const Variant& v : variants) {
    AspectBuildOptions options;
    options.kind = v.kind;
    options.edge_bases_only = v.edges_only;
    options.initial_spacing_deg = v.spacing_deg;
    AspectBuildReport r;
    Result<std::vector<uint8_t>> blob = BuildAspectBlob(models, options, &r);
    if (!blob.ok()) {
      std::printf("%-46s | %s\n", v.name, blob.status().message());
      continue;
    }
    if (v.kind == AspectBasisKind::kSimilarity && !v.edges_only) similarity_all = r;
    std::printf("%-46s | %8u | %-18u | %-17u | %-18u | %-17u\n", v.name, r.aspects, r.point_entries,
                r.max_point_bin_entries, r.line_entries, r.max_line_bin_entries);
  }
  std::printf("%-46s | %8u | %-18u | %-17u | %-18u | %-17u\n", "thesis, similarity", 188u,
              kThesisPointEntries, kThesisPointMaxBin, kThesisLineEntries, kThesisLineMaxBin);
  std::printf(
      "\nPer model, similarity over all corner pairs on the 15-degree grid (thesis table 6.1 in "
      "brackets):\n");
  for (size_t m = 0; m < similarity_all.per_model.size(); ++m) {
    const AspectModelReport& r = similarity_all.per_model[m];
    const ThesisModelRow* t = nullptr;
    for (const ThesisModelRow& row : kThesisModels) {
      if (r.model == row.model) t = &row;
    }
    std::printf("  %-10s %4u aspects (%3u), %6u bases (%5u), %u test views, %u refined\n",
                r.model.c_str(), r.aspects, t ? t->aspects : 0, r.bases, t ? t->bases : 0,
                r.test_views, r.failed_test_views);
  }
  std::printf(
      "\nThe thesis refined its 15-degree grid where test views failed, with criteria it then\n"
      "relaxed (6.4.1); with those criteria no test view fails on either grid here. The default\n"
      "tables start from a 10-degree grid. Line entries exclude the edges between basis corners\n"
      "(they lie on the basis axis in every basis), and features farther than 4 basis lengths\n"
      "from a basis's origin are not stored.\n");
  return 0;
}

}  // namespace sh::tools
