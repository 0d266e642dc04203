// `stereohash tables build` and `stereohash tables info`: offline preprocessing of model folders
// into one model set (hash tables, view database, feature database, aspect table as sections),
// and its inspection.
#include <Eigen/Core>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "recog/base/printable.hpp"
#include "recog/model/model_features.hpp"
#include "tables/aspect_file.hpp"
#include "tables/model_files.hpp"
#include "tables/model_set.hpp"
#include "tables/shape_views_file.hpp"
#include "tables/table_file.hpp"
#include "tools/command.hpp"
#include "tools/recognize_texture.hpp"
#include "tools/report_util.hpp"
#include "tools/tablegen/cad_import.hpp"
#include "tools/tablegen/model_set_writer.hpp"
#include "tools/tablegen/shape_view_builder.hpp"
#include "tools/tablegen/table_builder.hpp"
#include "tools/tables_aspects.hpp"
#include "tools/tables_cad.hpp"
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
      "usage: stereohash tables build --out FILE [--models DIR] [--names cube,hexagon,...]\n"
      "                               [--hash-fn 1..5] [--spacing-deg D] [--components N]\n"
      "                               [--hash-2d similarity|affine ... | --no-hash-2d]\n"
      "                               [--views-out FILE] [--units mm|cm|m|in] [--sharp-deg A]\n"
      "                               [--origin file|centroid]\n"
      "                               [--bare]\n"
      "Builds one model set (docs/tables.md) holding whatever the models need, each kind as a\n"
      "section; a folder may mix them:\n"
      "  polyhedra (plain OBJ)  -> HASH3D: the hash tables of one hash function (default 5)\n"
      "  colour parts (OBJ naming an MTL with a Kd colour) -> SHAPE_VIEWS: views over the\n"
      "                viewing sphere and in-plane rotation every D degrees (--spacing-deg,\n"
      "                default 10), PCA to N dimensions (--components, default 100)\n"
      "  printed models (OBJ with vt, MTL with map_Kd) -> TEXTURE_FEATURES: the feature database\n"
      "  polyhedra         -> ASPECTS_2D: their aspect table for the one-camera fallback and the\n"
      "                one-image rescue (similarity bases unless --hash-2d says; not with\n"
      "                --no-hash-2d or --bare)\n"
      "Models: those of DIR/models.txt, or every model file of DIR (default DIR: ./models), or\n"
      "--names. A model file is an OBJ or a CAD export as STL (binary or ASCII), PLY or 3MF\n"
      "(docs/tables.md); coplanar triangles are merged into faces; facets that bend by less\n"
      "than the sharp angle are a curved surface, seen as silhouettes and never hashed.\n"
      "%s"
      "  --views-out FILE  write the colour parts' view database to FILE instead\n"
      "%s"
      "  --bare        write the single-kind blob itself when the set has one section (the\n"
      "                format older builds read)\n",
      kAspectOptionsHelp, kCadOptionsHelp);
}

void InfoUsage() {
  std::printf(
      "usage: stereohash tables info [FILE ...] [--models DIR]\n"
      "Without FILE: builds the tables of all five hash functions and the 2-D aspect tables\n"
      "from the reference models and prints them beside the thesis's tables 5.3, 6.1 and 6.2.\n"
      "With FILE: lists a model set's sections and describes each (or describes a single-kind\n"
      "blob; the built-in ones when FILE is 'builtin' or 'builtin-aspects').\n");
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

// Holes in a face: each is spliced into the face's outline along a bridge whose two ends the
// outline then lists twice (ModelFace).
int FaceHoles(const ModelFace& face) {
  int repeats = 0;
  for (int k = 0; k < face.n_vertices; ++k) {
    for (int j = 0; j < k; ++j) repeats += face.vertices[j] == face.vertices[k] ? 1 : 0;
  }
  return repeats / 2;
}

// Area of a face in mm2 (Newell's method: a hole's bridge passes cancel).
double FaceAreaMm2(const Model& model, const ModelFace& face) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (int k = 0; k < face.n_vertices; ++k) {
    const Eigen::Vector3d p = model.corner(face.vertices[k]).cast<double>();
    const Eigen::Vector3d q = model.corner(face.vertices[(k + 1) % face.n_vertices]).cast<double>();
    n += p.cross(q);
  }
  return 0.5 * n.norm();
}

// What a part with curved surfaces offers hashing (model_features.hpp): its facets' area, its
// smooth edges and the corners and edges left to hash.
void PrintCurvedSurfaces(const Model& model) {
  const ModelFeatures features = FeaturesOf(model);
  if (features.n_smooth_edges == 0) return;
  int facets = 0;
  double area_mm2 = 0;
  for (int f = 0; f < model.n_faces; ++f) {
    if (!FaceIsCurved(model, f)) continue;
    ++facets;
    area_mm2 += FaceAreaMm2(model, model.faces[f]);
  }
  std::printf(
      "    curved surfaces: %d facets, %.0f mm2, %d smooth edges (silhouettes only); hashed: %d "
      "of %u corners, %d of %u edges\n",
      facets, area_mm2, features.n_smooth_edges, features.n_corners(), model.n_corners,
      features.n_lines(), model.n_edges);
}

void PrintModels(const TableView& view) {
  std::vector<uint32_t> bases(view.model_count());
  for (uint32_t b = 0; b < view.basis_count(); ++b) ++bases[view.basis(b).model];
  for (uint32_t m = 0; m < view.model_count(); ++m) {
    const Model& model = view.model(m);
    char shown[kPrintableNameBytes];  // names come from the blob: no raw control bytes
    std::printf(
        "  model %u %-10s %2u corners %2u edges %2u faces, symmetry group of order %2u, "
        "%4u bases\n",
        m, Printable(model.name, sizeof(model.name), shown, sizeof(shown)), model.n_corners,
        model.n_edges, model.n_faces, model.n_symmetries, bases[m]);
    int holed_faces = 0, holes = 0;
    for (int f = 0; f < model.n_faces; ++f) {
      const int n = FaceHoles(model.faces[f]);
      holed_faces += n > 0 ? 1 : 0;
      holes += n;
    }
    if (holed_faces > 0) {
      std::printf("    %d faces with holes, %d holes in all\n", holed_faces, holes);
    }
    PrintCurvedSurfaces(model);
    if (bases[m] == 0 && FeaturesOf(model).n_corners() < 3) {
      std::printf(
          "  warning: model %u is curved surfaces with fewer than 3 corners to hash: the stereo "
          "path cannot find it; as a colour part (an OBJ whose MTL gives Kd) the colour path can\n",
          m);
    } else if (bases[m] == 0) {
      const BasisLimits l = view.limits();
      std::printf(
          "  warning: model %u offers no basis within this table's limits (points %.0f..%.0f mm "
          "apart, a point %.0f..%.0f mm from a line): the stereo path cannot find it\n",
          m, double(l.min_point_spacing_mm), double(l.max_point_spacing_mm),
          double(l.min_point_line_mm), double(l.max_point_line_mm));
    }
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

void DescribeShapeViews(const ShapeViewsView& v, size_t size) {
  const ShapeViewsHeader& h = v.header();
  std::printf(
      "view database, format version %u, %zu bytes, CRC-32 %08x\n  %u colour parts, %u views "
      "every %.1f deg, %u PCA dimensions keeping %.1f %% of the views' variance\n",
      h.format_version, size, h.blob_crc32, h.n_models, h.n_views, double(h.view_spacing_deg),
      h.n_components, 100.0 * double(h.explained_energy));
  for (uint32_t m = 0; m < v.model_count(); ++m) {
    const ShapeModelRecord& r = v.shape_model(m);
    char shown[kPrintableNameBytes];  // names come from the blob: no raw control bytes
    std::printf("  model %u %-10s %6u views, colour (%.2f, %.2f, %.2f)\n", m,
                Printable(v.model(m).name, sizeof(Model::name), shown, sizeof(shown)), r.n_views,
                double(r.kd[0]), double(r.kd[1]), double(r.kd[2]));
  }
}

// Opens `blob` as a View and, if it is valid, prints it with `describe`; the view's Status.
template <typename View>
Status OpenAndDescribe(BlobSpan blob, void (*describe)(const View&, size_t)) {
  const Result<View> view = View::Open(blob.data, blob.size);
  if (view.ok()) describe(*view, blob.size);
  return view.status();
}

// Opens `blob` with the view of `kind` and prints what it holds; false (message printed) if the
// view refuses it.
bool DescribeBlob(uint32_t kind, BlobSpan blob) {
  Status s = Status::Ok();
  switch (static_cast<SectionKind>(kind)) {
    case SectionKind::kHash3d:
      s = OpenAndDescribe<TableView>(blob, Describe);
      break;
    case SectionKind::kTextureFeatures:
      s = OpenAndDescribe<FeatureDbView>(blob, DescribeFeatureDb);
      break;
    case SectionKind::kShapeViews:
      s = OpenAndDescribe<ShapeViewsView>(blob, DescribeShapeViews);
      break;
    case SectionKind::kAspects2d:
      s = OpenAndDescribe<AspectTableView>(blob, DescribeAspects);
      break;
    default:
      std::printf("kind %u, not known to this build: skipped\n", kind);
      return true;
  }
  if (!s.ok()) {
    std::printf("\n");
    std::fprintf(stderr, "stereohash tables info: %s: %s\n", SectionKindName(kind), s.message());
  }
  return s.ok();
}

// `tables info FILE`: a model set's sections, or a single-kind blob. Returns the exit code.
int DescribeFile(const std::string& file) {
  MappedFile mapped;
  Status s = mapped.Open(file.c_str(), "file");
  if (!s.ok()) {
    std::printf("\n");
    std::fprintf(stderr, "stereohash tables info: %s\n", s.message());
    return 1;
  }
  if (!IsModelSet(mapped.data(), mapped.size())) {
    const Result<uint32_t> kinds = BlobKinds(mapped.data(), mapped.size());
    for (const SectionKindInfo& k : kSectionKinds) {
      if (kinds.ok() && *kinds == KindBit(k.kind)) {
        return DescribeBlob(uint32_t(k.kind), {mapped.data(), mapped.size()}) ? 0 : 1;
      }
    }
    std::printf("\n");
    std::fprintf(stderr, "stereohash tables info: %s: not a model set or a stereohash blob\n",
                 file.c_str());
    return 1;
  }
  const Result<ModelSetView> set = ModelSetView::Open(mapped.data(), mapped.size());
  if (!set.ok()) {
    std::printf("\n");
    std::fprintf(stderr, "stereohash tables info: %s: %s\n", file.c_str(), set.status().message());
    return 1;
  }
  const ModelSetHeader& h = set->header();
  std::printf("model set, format version %u, %zu bytes, CRC-32 %08x, %u section%s\n",
              h.format_version, mapped.size(), h.blob_crc32, h.section_count,
              h.section_count == 1 ? "" : "s");
  int rc = 0;
  for (uint32_t i = 0; i < set->section_count(); ++i) {
    const ModelSetSection& d = set->section(i);
    std::printf("section %u: %s (kind %u, version %u) at %llu, %llu bytes, CRC-32 %08x\n  ", i,
                SectionKindName(d.kind), d.kind, d.kind_version,
                static_cast<unsigned long long>(d.offset), static_cast<unsigned long long>(d.size),
                d.crc32);
    if (!DescribeBlob(d.kind, set->payload(i))) rc = 1;
  }
  return rc;
}

// The names of `list` whose DIR/<name>.obj is not one of `printed` (paths).
// The names of `dir`'s models that are not among the `printed` OBJ files.
Status PlainModelNames(const std::string& dir, const std::vector<std::string>& printed,
                       std::vector<std::string>* names) {
  std::vector<std::string> all;
  SH_RETURN_IF_ERROR(ModelFolderNames(dir, &all));
  names->clear();
  for (const std::string& name : all) {
    const std::string path = std::string(dir).append("/").append(name).append(".obj");
    if (std::find(printed.begin(), printed.end(), path) == printed.end()) names->push_back(name);
  }
  return Status::Ok();
}

struct BuiltSection {
  uint32_t kind;
  std::vector<uint8_t> bytes;
};

// Writes `sections` to `path`: a model set, or with `bare` the one section's blob itself.
bool WriteSections(const std::string& path, const std::vector<BuiltSection>& sections, bool bare) {
  if (bare && sections.size() != 1) {
    std::fprintf(stderr,
                 "stereohash tables build: --bare writes one kind; %s would hold %zu sections\n",
                 path.c_str(), sections.size());
    return false;
  }
  std::vector<uint8_t> blob;
  if (bare) {
    blob = sections[0].bytes;
  } else {
    std::vector<ModelSetInput> inputs;
    inputs.reserve(sections.size());
    for (const BuiltSection& s : sections)
      inputs.push_back({s.kind, s.bytes.data(), s.bytes.size()});
    Result<std::vector<uint8_t>> set = BuildModelSet(inputs);
    if (!set.ok()) {
      std::fprintf(stderr, "stereohash tables build: %s\n", set.status().message());
      return false;
    }
    blob = std::move(*set);
  }
  if (!WriteFileBytes(path.c_str(), blob.data(), blob.size())) {
    std::fprintf(stderr, "stereohash tables build: cannot write '%s'\n", path.c_str());
    return false;
  }
  std::printf("wrote %s: %s, %zu bytes:", path.c_str(), bare ? "single-kind blob" : "model set",
              blob.size());
  for (const BuiltSection& s : sections) std::printf(" %s", SectionKindName(s.kind));
  std::printf("\n");
  return true;
}

constexpr const char* kBuild = "tables build";

// The HASH3D section of `models` for hash function `hf`; prints what each model became (a
// changed model shows there: other counts, a smaller symmetry group), or the error.
Result<std::vector<uint8_t>> BuildHashSection(const std::vector<Model>& models, int hf) {
  TableBuildOptions options;
  options.hash_function = static_cast<HashFunction>(hf);
  TableBuildReport report;
  Result<std::vector<uint8_t>> blob = BuildTableBlob(models, options, &report);
  if (!blob.ok()) {
    std::fprintf(stderr, "stereohash tables build: %s\n", blob.status().message());
    return blob;
  }
  std::printf("  HASH3D: ");
  if (!DescribeBlob(uint32_t(SectionKind::kHash3d), {blob->data(), blob->size()})) {
    return Status::Error(StatusCode::kInternal, "the HASH3D section as built does not open");
  }
  return blob;
}

// `all` (the models `list` of `dir`) split into polyhedra and colour parts, whose OBJ names a
// material with a diffuse colour; CAD exports carry no material and are polyhedra.
Status SplitColourParts(const std::string& dir, const std::vector<std::string>& list,
                        const std::vector<Model>& all, std::vector<Model>* polyhedra,
                        std::vector<ShapeModelInput>* parts) {
  for (size_t i = 0; i < all.size(); ++i) {
    ShapeModelInput part;
    part.model = all[i];
    SH_ASSIGN_OR_RETURN(const std::string path, ModelFilePath(dir, list[i]));
    const Status colour = IsCadFileName(path) ? Status::Error(StatusCode::kNotFound, "no material")
                                              : LoadModelColour(path, all[i], part.kd);
    if (colour.ok()) {
      parts->push_back(part);
    } else if (colour.code() == StatusCode::kNotFound) {
      polyhedra->push_back(all[i]);
    } else {
      return colour;
    }
  }
  return Status::Ok();
}

// The command line of `stereohash tables build`, with its defaults.
struct BuildArgs {
  std::string out, models_dir = "models", names, views_out;
  bool models_given = false, bare = false, want_aspects = false, no_aspects = false;
  // --hash-2d was given; after parsing, want_aspects also holds when the set gets its aspect
  // table by default.
  bool aspects_asked = false;
  int hf = 5;
  ShapeViewBuildOptions view_options;
  AspectBuildOptions aspect_options;
  CadImportOptions cad;
};

// Reads the options into `args`; false (with the exit code) for --help or a bad option.
bool ParseBuildArgs(int argc, char** argv, BuildArgs* args, int* exit_code) {
  *exit_code = 2;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const int aspect =
        ParseAspectOption(argc, argv, &i, &args->aspect_options, &args->want_aspects);
    if (aspect < 0) return false;
    if (aspect > 0) continue;
    const int cad_option = ParseCadOption(argc, argv, &i, &args->cad);
    if (cad_option < 0) return false;
    if (cad_option > 0) continue;
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "stereohash tables build: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      BuildUsage();
      *exit_code = 0;
      return false;
    } else if (a == "--out") {
      args->out = value();
    } else if (a == "--hash-fn") {
      long n = 0;
      if (!OptionInteger(kBuild, "--hash-fn", value().c_str(), 1, 5, &n)) return false;
      args->hf = int(n);
    } else if (a == "--models") {
      args->models_dir = value();
      args->models_given = true;
    } else if (a == "--views-out") {
      args->views_out = value();
    } else if (a == "--spacing-deg") {
      double deg = 0;
      if (!OptionNumber(kBuild, "--spacing-deg", value().c_str(), 0.1, 180, &deg)) return false;
      args->view_options.view_spacing_deg = static_cast<float>(deg);
    } else if (a == "--components") {
      long n = 0;
      if (!OptionInteger(kBuild, "--components", value().c_str(), 1, 1000000, &n)) return false;
      args->view_options.n_components = int(n);
    } else if (a == "--names") {
      args->names = value();
    } else if (a == "--bare") {
      args->bare = true;
    } else if (a == "--no-hash-2d") {
      args->no_aspects = true;
    } else {
      std::fprintf(stderr, "stereohash tables build: unknown option '%s'\n", a.c_str());
      BuildUsage();
      return false;
    }
  }
  if (args->out.empty() || !IsValidHashFunction(args->hf)) {
    std::fprintf(stderr, "stereohash tables build: need --out FILE and --hash-fn 1..5\n");
    return false;
  }
  if (args->want_aspects && args->no_aspects) {
    std::fprintf(stderr,
                 "stereohash tables build: --hash-2d and --no-hash-2d exclude each other\n");
    return false;
  }
  // A set with polyhedra carries their aspect table unless told not to (or bare): the one-camera
  // fallback and the stereo path's one-image rescue then work with the set's own models.
  args->aspects_asked = args->want_aspects;
  args->want_aspects = args->want_aspects || (!args->no_aspects && !args->bare);
  return true;
}

// The models to build from: the printed models' paths (a --models folder's; they go to the
// feature database) and the names of the others. 0 or the command's exit code.
int ListBuildModels(const BuildArgs& args, std::vector<std::string>* printed,
                    std::vector<std::string>* list) {
  std::vector<std::string> plain;
  if (args.names.empty() && args.models_given) {
    const Status s = ClassifyModelFolder(args.models_dir, printed, &plain);
    if (!s.ok()) {
      std::fprintf(stderr, "stereohash tables build: %s\n", s.message());
      return 1;
    }
  }
  if (!args.names.empty()) {
    *list = Split(args.names);
    const Status checked = CheckModelNames(*list, "--names");
    if (!checked.ok()) {
      std::fprintf(stderr, "stereohash tables build: %s\n", checked.message());
      return 2;
    }
  } else if (!args.models_given || !plain.empty()) {
    const Status named = PlainModelNames(args.models_dir, *printed, list);
    if (!named.ok()) {
      std::fprintf(stderr, "stereohash tables build: %s\n", named.message());
      return 1;
    }
  }
  return 0;
}

// The sections of the set (views_sections: the view database when --views-out names its own
// file); false after printing why one could not be built.
bool BuildSections(const BuildArgs& args, const std::vector<Model>& models,
                   const std::vector<ShapeModelInput>& parts,
                   const std::vector<std::string>& printed, std::vector<BuiltSection>* sections,
                   std::vector<BuiltSection>* views_sections) {
  if (!models.empty()) {
    Result<std::vector<uint8_t>> blob = BuildHashSection(models, args.hf);
    if (!blob.ok()) return false;
    sections->push_back({uint32_t(SectionKind::kHash3d), std::move(*blob)});
  }
  if (!parts.empty()) {
    ShapeViewBuildReport report;
    Result<std::vector<uint8_t>> blob = BuildShapeViewBlob(parts, args.view_options, &report);
    if (!blob.ok()) {
      std::fprintf(stderr, "stereohash tables build: %s\n", blob.status().message());
      return false;
    }
    std::printf("  SHAPE_VIEWS: ");
    if (!DescribeBlob(uint32_t(SectionKind::kShapeViews), {blob->data(), blob->size()})) {
      return false;
    }
    (args.views_out.empty() ? sections : views_sections)
        ->push_back({uint32_t(SectionKind::kShapeViews), std::move(*blob)});
  }
  if (!printed.empty()) {
    Result<std::vector<uint8_t>> blob = BuildPrintedSection(printed);
    if (!blob.ok()) {
      std::fprintf(stderr, "stereohash tables build: %s\n", blob.status().message());
      return false;
    }
    sections->push_back({uint32_t(SectionKind::kTextureFeatures), std::move(*blob)});
  }
  if (args.want_aspects && !models.empty()) {
    Result<std::vector<uint8_t>> blob = BuildAspectSection(models, args.aspect_options);
    if (!blob.ok()) {
      std::fprintf(stderr, "stereohash tables build: %s\n", blob.status().message());
      return false;
    }
    sections->push_back({uint32_t(SectionKind::kAspects2d), std::move(*blob)});
  }
  return true;
}

int RunBuild(int argc, char** argv) {
  BuildArgs args;
  int exit_code = 0;
  if (!ParseBuildArgs(argc, argv, &args, &exit_code)) return exit_code;
  // Printed models (OBJ with texture coordinates and an image) of a folder: the feature database.
  std::vector<std::string> printed, list;
  const int listed = ListBuildModels(args, &printed, &list);
  if (listed != 0) return listed;
  // Colour parts (a material with a diffuse colour) go to the view database.
  std::vector<Model> all, models;
  std::vector<ShapeModelInput> parts;
  Status loaded = LoadFolderModels(args.models_dir, list, args.cad, &all);
  if (loaded.ok()) loaded = SplitColourParts(args.models_dir, list, all, &models, &parts);
  if (!loaded.ok()) {
    std::fprintf(stderr, "stereohash tables build: %s\n", loaded.message());
    return 1;
  }
  if (args.aspects_asked && models.empty()) {
    std::fprintf(stderr, "stereohash tables build: --hash-2d needs polyhedra; %s holds none\n",
                 args.models_dir.c_str());
    return 2;
  }
  if (models.empty() && parts.empty() && printed.empty()) {
    std::fprintf(stderr, "stereohash tables build: no models in %s\n", args.models_dir.c_str());
    return 2;
  }
  std::printf("building %s from %s: %zu polyhedra, %zu colour parts, %zu printed models\n",
              args.out.c_str(), args.models_dir.c_str(), models.size(), parts.size(),
              printed.size());
  std::vector<BuiltSection> sections, views_sections;
  if (!BuildSections(args, models, parts, printed, &sections, &views_sections)) return 1;
  if (!views_sections.empty() && !WriteSections(args.views_out, views_sections, args.bare)) {
    return 1;
  }
  if (sections.empty()) return 0;
  return WriteSections(args.out, sections, args.bare) ? 0 : 1;
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
    if (file == "builtin" || file == "builtin-aspects") {
      const bool aspects = file == "builtin-aspects";
      const BlobSpan blob = aspects ? BlobSpan{DefaultAspectBlob(), DefaultAspectBlobSize()}
                                    : BlobSpan{DefaultTableBlob(), DefaultTableBlobSize()};
      if (!DescribeBlob(uint32_t(aspects ? SectionKind::kAspects2d : SectionKind::kHash3d), blob))
        rc = 1;
    } else if (DescribeFile(file) != 0) {
      rc = 1;
    }
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

SH_REGISTER_COMMAND(tables,
                    "build or describe model sets (thesis tables 5.3, 6.1, 6.2 beside ours)",
                    RunTables);

}  // namespace sh::tools
