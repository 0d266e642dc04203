// Loading model folders from disk (host tools, the build step that bakes the default tables and
// the simulator's world at boot; never per frame). One loader, so that a folder gives the same
// model order, and so the same model ids, to everything that reads it.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh {

// The manifest of a model folder: model names (OBJ file stems) in model-id order.
inline constexpr const char* kModelManifestName = "models.txt";
// Most models one folder may hold, and the largest OBJ file read.
inline constexpr int kMaxFolderModels = 32;
inline constexpr long kMaxObjFileBytes = 1 << 20;
// A folder's models.txt.
inline constexpr size_t kMaxModelManifestBytes = size_t{1} << 16;

// Reads one OBJ file; the model is named after the file stem.
Result<Model> LoadModelFile(const std::string& path);

// The model name of an OBJ file: its stem, whole. A stem longer than kMaxModelNameLength is
// refused rather than cut, so that two long names never become one.
Result<std::string> ModelNameOfFile(const std::string& path);

// A list of model names given by the user (`--names`): each a model name (no spaces or '/', at
// most kMaxModelNameLength characters), none twice, as models.txt requires.
Status CheckModelNames(const std::vector<std::string>& names, const char* source);

// The diffuse colour (MTL Kd) of a single-colour part: the OBJ's one material (`usemtl`), read
// from the library its `mtllib` names (relative to the OBJ's folder). kNotFound when the OBJ
// names no material or library; kInvalidArgument when it uses more than one material.
Status LoadModelColour(const std::string& obj_path, const Model& model, float kd[3]);

// The extensions a model file may have (any case): OBJ, read here, and the CAD exports that the
// host tools read (tools/tablegen/cad_import.hpp).
inline constexpr const char* kModelFileExtensions[] = {".obj", ".stl", ".ply", ".3mf"};

// The entry of kModelFileExtensions that `path` ends in (any case; the lower-case entry is
// returned), or null.
const char* ModelFileExtension(const std::string& path);
// Whether `path` is an OBJ file (".obj", any case): the format every reader takes, where the
// others need the host's CAD import.
bool IsObjModelFile(const std::string& path);

// The file of model `name` in `dir`: `<dir>/<name>.<ext>` for the one extension of
// kModelFileExtensions present. kNotFound when there is none; kInvalidArgument when two are
// (cube.obj beside cube.stl), since which one is meant cannot be guessed.
Result<std::string> ModelFilePath(const std::string& dir, const std::string& name);

// Reads one model file; the default reads OBJ (LoadModelFile) and refuses the CAD formats,
// naming the host command that reads them.
using ModelFileReader = std::function<Result<Model>(const std::string& path)>;

// Reads each name's file (ModelFilePath), in that order.
Status LoadModels(const std::string& dir, const std::vector<std::string>& names,
                  std::vector<Model>* models, const ModelFileReader& read = nullptr);

// The names a folder's manifest lists (comments after '#', blank lines skipped), or, for a
// folder without a manifest, the stems of its model files (kModelFileExtensions) in file-name
// order.
Status ModelFolderNames(const std::string& dir, std::vector<std::string>* names);

// Every model of a folder, in the order of ModelFolderNames (model i has id i).
Status LoadModelFolder(const std::string& dir, std::vector<Model>* models);

// Index of the model called `name`, or -1.
int FindModelByName(const std::vector<Model>& models, const char* name);

}  // namespace sh
