#include "tools/tables_cad.hpp"

#include <cstdio>
#include <cstring>

#include "tables/model_files.hpp"
#include "tools/command.hpp"
#include "tools/tablegen/model_symmetry.hpp"

namespace sh::tools {

const char* const kCadOptionsHelp =
    "  --units U     the length unit of the model files (STL has none): mm (default), cm, m, in\n"
    "  --sharp-deg A the least bend of a feature edge between facets, degrees (default 20,\n"
    "                2..89); facets that bend by less are a curved surface\n"
    "                (with --units or --sharp-deg, OBJ files are read as CAD exports too)\n"
    "  --origin O    a CAD export's model origin: file (default: poses are of the CAD frame)\n"
    "                or centroid (its centre of volume, printed, which lies on every symmetry\n"
    "                axis; the build warns when a part's symmetry needs it)\n";

int ParseCadOption(int argc, char** argv, int* i, CadImportOptions* options) {
  const char* a = argv[*i];
  const bool known = std::strcmp(a, "--units") == 0 || std::strcmp(a, "--sharp-deg") == 0 ||
                     std::strcmp(a, "--origin") == 0;
  if (!known) return 0;
  if (*i + 1 >= argc) {
    std::fprintf(stderr, "stereohash tables build: %s needs a value\n", a);
    return -1;
  }
  const char* value = argv[++*i];
  if (std::strcmp(a, "--units") == 0) {
    if (!ParseLengthUnit(value, &options->mm_per_unit)) {
      std::fprintf(stderr, "stereohash tables build: --units takes mm, cm, m or in\n");
      return -1;
    }
    options->unit = value;
    options->obj_through_import = true;
  } else if (std::strcmp(a, "--sharp-deg") == 0) {
    if (!OptionNumber("tables build", "--sharp-deg", value, kMinSharpDeg, kMaxSharpDeg,
                      &options->sharp_deg)) {
      return -1;
    }
    options->obj_through_import = true;
  } else if (std::strcmp(value, "centroid") == 0 || std::strcmp(value, "file") == 0) {
    options->origin = value[0] == 'f' ? ModelOrigin::kFile : ModelOrigin::kCentroid;
    options->obj_through_import = true;
  } else {
    std::fprintf(stderr, "stereohash tables build: --origin takes centroid or file\n");
    return -1;
  }
  return 1;
}

namespace {

// Symmetries are rotations about the model origin: a part kept in a file frame whose origin lies
// off its symmetry axes loses them, and the tables then hold its equal bases apart.
void WarnOfHiddenSymmetry(const std::string& path, const Model& model,
                          const Eigen::Vector3d& centroid_mm) {
  Model centred = model;
  MoveModelOrigin(centred, centroid_mm);
  const size_t in_file = FindSymmetries(model).size();
  const size_t about_centroid = FindSymmetries(centred).size();
  if (about_centroid > in_file) {
    std::printf(
        "  warning: %s has a symmetry group of order %zu about its centroid, (%.3f, %.3f, "
        "%.3f) mm, but of order %zu about the file's origin: --origin centroid keeps it\n",
        path.c_str(), about_centroid, centroid_mm.x(), centroid_mm.y(), centroid_mm.z(), in_file);
  }
}

}  // namespace

Status LoadFolderModels(const std::string& dir, const std::vector<std::string>& names,
                        const CadImportOptions& options, std::vector<Model>* models) {
  return LoadModels(dir, names, models, [&options](const std::string& path) {
    CadImportReport report;
    Result<Model> model = ImportModelFile(path, options, &report);
    if (!model.ok() || (!IsCadFileName(path) && !options.obj_through_import)) return model;
    const Eigen::Vector3d& o = report.origin_in_file_mm;
    if (options.origin == ModelOrigin::kCentroid) {
      std::printf("  %s: model origin at its centroid, (%.3f, %.3f, %.3f) mm in the file's frame\n",
                  path.c_str(), o.x(), o.y(), o.z());
    } else {
      WarnOfHiddenSymmetry(path, *model, report.centroid_in_file_mm);
    }
    return model;
  });
}

}  // namespace sh::tools
