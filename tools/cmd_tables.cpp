// `stereohash tables build` and `stereohash tables info`: offline preprocessing and inspection
// of hash table blobs and shape view databases.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "tables/model_files.hpp"
#include "tables/shape_view_builder.hpp"
#include "tables/shape_views_file.hpp"
#include "tables/table_builder.hpp"
#include "tables/table_file.hpp"
#include "tools/command.hpp"
#include "tools/recognize_texture.hpp"
#include "tools/report_util.hpp"
#include "tools/tables_aspects.hpp"
#include "tools/tables_printed.hpp"

namespace sh::tools {
namespace {

// Thesis table 5.3: entries and the largest bin per hash function (points, lines).
struct ThesisRow {
  uint32_t point_entries, point_max_bin, line_entries, line_max_bin;
};
constexpr ThesisRow kThesis[6] = {{},
                                  {15328, 110, 26280, 3285},
                                  {15328, 49, 26280, 869},
                                  {7600, 265, 11400, 1178},
                                  {3136, 153, 4832, 428},
                                  {3136, 72, 4832, 291}};

void BuildUsage() {
  std::printf(
      "usage: stereohash tables build --out FILE [--hash-fn 1..5] [--models DIR]\n"
      "                               [--names cube,hexagon,...] [--views-out FILE]\n"
      "                               [--spacing-deg D] [--components N]\n"
      "Builds the hash table blob of one hash function (default 5) for the models\n"
      "DIR/<name>.obj (default: the models of ./models/models.txt; with --models DIR and no\n"
      "--names, the models of DIR's models.txt or every DIR/*.obj). Models whose OBJ names a\n"
      "material (mtllib, usemtl with an MTL Kd colour) are single-colour parts: their view\n"
      "database (views over the viewing sphere and in-plane rotation every D degrees, default\n"
      "10, PCA to N dimensions, default 100) goes to --out when every model is one, else to\n"
      "--views-out.\n"
      "A folder of printed models (OBJ with vt, MTL with map_Kd: models/textured) gives their\n"
      "feature database.\n"
      "       stereohash tables build --hash-2d similarity|affine --out FILE ...\n"
      "Builds the aspect table of the monocular mode ('--hash-2d x --help' for more).\n");
}

void InfoUsage() {
  std::printf(
      "usage: stereohash tables info [FILE ...] [--models DIR]\n"
      "Without FILE: builds the tables of all five hash functions and the 2-D aspect tables\n"
      "from the reference models and prints them beside the thesis's tables 5.3, 6.1 and 6.2.\n"
      "With FILE: describes that blob or aspect table (the built-in ones when FILE is\n"
      "'builtin' or 'builtin-aspects').\n");
}

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= s.size()) {
    const size_t comma = s.find(',', start);
    const std::string part =
        s.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!part.empty()) out.push_back(part);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

void PrintGrid(const char* what, const GridGeometry& g) {
  std::printf("  %s grid: %u x %u x %u bins of %.0f mm from (%.0f, %.0f, %.0f) mm\n", what,
              g.dims[0], g.dims[1], g.dims[2], double(g.bin_mm), double(g.min_mm[0]),
              double(g.min_mm[1]), double(g.min_mm[2]));
}

void PrintModels(const TableView& view) {
  std::vector<uint32_t> bases(view.model_count());
  for (uint32_t b = 0; b < view.basis_count(); ++b) ++bases[view.basis(b).model];
  for (uint32_t m = 0; m < view.model_count(); ++m) {
    const Model& model = view.model(m);
    std::printf(
        "  model %u %-10s %2u corners %2u edges %2u faces, symmetry group of order %2u, "
        "%4u bases\n",
        m, model.name, model.n_corners, model.n_edges, model.n_faces, model.n_symmetries, bases[m]);
  }
}

void Describe(const TableView& view, size_t size) {
  const TableHeader& h = view.header();
  std::printf("hash function %u, format version %u, %zu bytes, CRC-32 %08x\n", h.hash_function,
              h.format_version, size, h.blob_crc32);
  std::printf(
      "  %u models, %u model bases, %u point entries (largest bin %u), %u line entries "
      "(largest bin %u)\n",
      h.n_models, h.n_bases, h.n_point_entries, h.max_point_bin_entries, h.n_line_entries,
      h.max_line_bin_entries);
  PrintGrid("point", h.point_grid);
  PrintGrid("line ", h.line_grid);
  PrintModels(view);
}

int RunBuild(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--hash-2d") == 0) return BuildAspectTable(argc, argv);
  }
  std::string out, models_dir = "models", names, views_out;
  bool models_given = false;
  int hf = 5;
  ShapeViewBuildOptions view_options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "stereohash tables build: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      BuildUsage();
      return 0;
    } else if (a == "--out") {
      out = value();
    } else if (a == "--hash-fn") {
      hf = std::atoi(value().c_str());
    } else if (a == "--models") {
      models_dir = value();
      models_given = true;
    } else if (a == "--views-out") {
      views_out = value();
    } else if (a == "--spacing-deg") {
      view_options.view_spacing_deg = static_cast<float>(std::atof(value().c_str()));
    } else if (a == "--components") {
      view_options.n_components = std::atoi(value().c_str());
    } else if (a == "--names") {
      names = value();
    } else {
      std::fprintf(stderr, "stereohash tables build: unknown option '%s'\n", a.c_str());
      BuildUsage();
      return 2;
    }
  }
  // A folder of printed models (OBJ with texture coordinates and an image) gives their feature
  // database; the hash tables are for the others.
  if (names.empty() && models_given && !out.empty()) {
    std::vector<std::string> printed, plain;
    const Status s = ClassifyModelFolder(models_dir, &printed, &plain);
    if (!s.ok()) {
      std::fprintf(stderr, "stereohash tables build: %s\n", s.message());
      return 1;
    }
    if (!printed.empty() && !plain.empty()) {
      std::fprintf(stderr,
                   "stereohash tables build: %s holds printed and plain models; build each kind "
                   "from its own folder\n",
                   models_dir.c_str());
      return 2;
    }
    if (!printed.empty()) return BuildPrintedTables(printed, out);
  }
  if (out.empty() || !IsValidHashFunction(hf)) {
    std::fprintf(stderr, "stereohash tables build: need --out FILE and --hash-fn 1..5\n");
    return 2;
  }
  std::vector<std::string> list;
  const Status named = names.empty() ? ModelFolderNames(models_dir, &list) : Status::Ok();
  if (!named.ok()) {
    std::fprintf(stderr, "stereohash tables build: %s\n", named.message());
    return 1;
  }
  if (!names.empty()) list = Split(names);
  std::vector<Model> all;
  const Status loaded = LoadModels(models_dir, list, &all);
  if (!loaded.ok()) {
    std::fprintf(stderr, "stereohash tables build: %s\n", loaded.message());
    return 1;
  }
  // Colour parts (a material with a diffuse colour) go to the view database.
  std::vector<Model> models;
  std::vector<ShapeModelInput> parts;
  for (size_t i = 0; i < all.size(); ++i) {
    ShapeModelInput part;
    part.model = all[i];
    const Status colour = LoadModelColour(models_dir + "/" + list[i] + ".obj", all[i], part.kd);
    if (colour.ok()) {
      parts.push_back(part);
    } else if (colour.code() == StatusCode::kNotFound) {
      models.push_back(all[i]);
    } else {
      std::fprintf(stderr, "stereohash tables build: %s\n", colour.message());
      return 1;
    }
  }
  if (!parts.empty()) {
    const std::string& path = models.empty() ? out : views_out;
    if (path.empty()) {
      std::fprintf(stderr,
                   "stereohash tables build: %zu models are colour parts and %zu polyhedra: give "
                   "--views-out FILE for the colour parts' view database\n",
                   parts.size(), models.size());
      return 2;
    }
    ShapeViewBuildReport report;
    Result<std::vector<uint8_t>> blob = BuildShapeViewBlob(parts, view_options, &report);
    if (!blob.ok()) {
      std::fprintf(stderr, "stereohash tables build: %s\n", blob.status().message());
      return 1;
    }
    if (!WriteFileBytes(path.c_str(), blob->data(), blob->size())) {
      std::fprintf(stderr, "stereohash tables build: cannot write '%s'\n", path.c_str());
      return 1;
    }
    std::printf(
        "wrote %s: view database, %zu bytes, %u views of %zu colour parts every %.1f "
        "deg, %d PCA dimensions keeping %.1f %% of the views' variance\n",
        path.c_str(), blob->size(), report.views, parts.size(),
        double(view_options.view_spacing_deg), view_options.n_components,
        100.0 * report.explained_energy);
    for (const ShapeModelViewCount& m : report.per_model) {
      std::printf("  %-10s %6u views (symmetry group of order %u)\n", m.model.c_str(), m.views,
                  m.symmetries);
    }
    if (models.empty()) return 0;
  }
  TableBuildOptions options;
  options.hash_function = static_cast<HashFunction>(hf);
  TableBuildReport report;
  auto blob = BuildTableBlob(models, options, &report);
  if (!blob.ok()) {
    std::fprintf(stderr, "stereohash tables build: %s\n", blob.status().message());
    return 1;
  }
  if (!WriteFileBytes(out.c_str(), blob->data(), blob->size())) {
    std::fprintf(stderr, "stereohash tables build: cannot write '%s'\n", out.c_str());
    return 1;
  }
  std::printf("wrote %s: hash fn %d, %zu bytes, %u bases, %u point and %u line entries\n",
              out.c_str(), hf, blob->size(), report.bases, report.point_entries,
              report.line_entries);
  // What each model became (a changed model shows here: other counts, a smaller symmetry group).
  const Result<TableView> view = TableView::Open(blob->data(), blob->size());
  if (view.ok()) PrintModels(*view);
  return 0;
}

int CompareWithThesis(const std::string& models_dir) {
  std::vector<Model> models;
  const Status loaded = LoadModelFolder(models_dir, &models);
  if (!loaded.ok()) {
    std::fprintf(stderr, "stereohash tables info: %s\n", loaded.message());
    return 1;
  }
  std::printf("Hash arrays of the six reference models, ours beside the thesis (table 5.3).\n\n");
  std::printf(
      "hf | point entries      | largest point bin | line entries       | largest line bin "
      "| point grid (5 mm bins) | line grid (10 mm bins) | blob bytes\n");
  std::printf(
      "   | ours      thesis   | ours   thesis     | ours      thesis   | ours   thesis    "
      "|                        |                        |\n");
  for (int hf = 1; hf <= 5; ++hf) {
    TableBuildOptions options;
    options.hash_function = static_cast<HashFunction>(hf);
    TableBuildReport r;
    auto blob = BuildTableBlob(models, options, &r);
    if (!blob.ok()) {
      std::fprintf(stderr, "hash fn %d: %s\n", hf, blob.status().message());
      return 1;
    }
    const TableHeader* h = reinterpret_cast<const TableHeader*>(blob->data());
    char pgrid[32], lgrid[32];
    std::snprintf(pgrid, sizeof(pgrid), "%u x %u x %u", h->point_grid.dims[0],
                  h->point_grid.dims[1], h->point_grid.dims[2]);
    std::snprintf(lgrid, sizeof(lgrid), "%u x %u x %u", h->line_grid.dims[0], h->line_grid.dims[1],
                  h->line_grid.dims[2]);
    const ThesisRow& t = kThesis[hf];
    std::printf("%2d | %-8u  %-8u | %-5u  %-10u | %-8u  %-8u | %-5u  %-9u | %-22s | %-22s | %zu\n",
                hf, r.point_entries, t.point_entries, r.max_point_bin_entries, t.point_max_bin,
                r.line_entries, t.line_entries, r.max_line_bin_entries, t.line_max_bin, pgrid,
                lgrid, blob->size());
  }
  std::printf("\nModel bases per model (thesis tables 2.1 and 5.2 in brackets):\n");
  const uint32_t thesis_bases[6][3] = {{42, 36, 18},    {110, 64, 30}, {20, 36, 12},
                                       {684, 220, 100}, {72, 52, 24},  {168, 176, 72}};
  std::printf("model      | hf 1, 2     | hf 3        | hf 4, 5\n");
  TableBuildReport per_hf[6];
  for (int hf : {1, 3, 4}) {
    TableBuildOptions options;
    options.hash_function = static_cast<HashFunction>(hf);
    (void)BuildTableBlob(models, options, &per_hf[hf]);
  }
  for (size_t m = 0; m < models.size(); ++m) {
    std::printf("%-10s | %4u (%4u) | %4u (%4u) | %4u (%4u)\n", models[m].name,
                per_hf[1].per_model[m].bases, thesis_bases[m][0], per_hf[3].per_model[m].bases,
                thesis_bases[m][1], per_hf[4].per_model[m].bases, thesis_bases[m][2]);
  }
  std::printf(
      "\nHash fn 3 stores every ordered pair of edges at least %.0f degrees apart with all four\n"
      "direction signs, one frame per class of symmetric bases; the thesis does not state its\n"
      "exclusion rule for near-parallel lines, so its hash fn 3 counts are not reproduced.\n"
      "The largest-bin figures depend on bin placement, which the thesis does not give.\n",
      double(BasisLimits{}.min_line_angle_deg));
  return 0;
}

int RunInfo(int argc, char** argv) {
  std::vector<std::string> files;
  std::string models_dir = "models";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      InfoUsage();
      return 0;
    } else if (a == "--models" && i + 1 < argc) {
      models_dir = argv[++i];
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "stereohash tables info: unknown option '%s'\n", a.c_str());
      InfoUsage();
      return 2;
    } else {
      files.push_back(a);
    }
  }
  if (files.empty()) {
    const int rc = CompareWithThesis(models_dir);
    return rc != 0 ? rc : CompareAspectsWithThesis(models_dir);
  }
  int rc = 0;
  for (const std::string& file : files) {
    std::printf("%s: ", file.c_str());
    if (DescribeAspectFile(file, &rc)) continue;
    if (file == "builtin") {
      auto view = OpenDefaultTable();
      if (!view.ok()) {
        std::printf("\n");
        std::fprintf(stderr, "stereohash tables info: %s\n", view.status().message());
        rc = 1;
        continue;
      }
      Describe(*view, DefaultTableBlobSize());
      continue;
    }
    if (IsFeatureDbFile(file.c_str())) {
      MappedFeatureDb db;
      const Status s = db.Open(file.c_str());
      if (!s.ok()) {
        std::printf("\n");
        std::fprintf(stderr, "stereohash tables info: %s\n", s.message());
        rc = 1;
        continue;
      }
      DescribeFeatureDb(db.view(), db.size());
      continue;
    }
    MappedTable table;
    const Status s = table.Open(file.c_str());
    if (!s.ok()) {
      std::printf("\n");
      std::fprintf(stderr, "stereohash tables info: %s\n", s.message());
      rc = 1;
      continue;
    }
    Describe(table.view(), table.size());
  }
  return rc;
}

int RunTables(int argc, char** argv) {
  if (argc >= 2 && std::strcmp(argv[1], "build") == 0) return RunBuild(argc - 1, argv + 1);
  if (argc >= 2 && std::strcmp(argv[1], "info") == 0) return RunInfo(argc - 1, argv + 1);
  std::printf("usage: stereohash tables build|info [options]  ('--help' after either for more)\n");
  return argc >= 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) ? 0
                                                                                               : 2;
}

}  // namespace

SH_REGISTER_COMMAND(tables, "build or describe hash table blobs (thesis table 5.3 beside ours)",
                    RunTables);

}  // namespace sh::tools
