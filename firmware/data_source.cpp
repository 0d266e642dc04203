#include "firmware/data_source.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "firmware/config_keys.hpp"
#include "recog/camera/binning.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "tables/input_file.hpp"

namespace sh::fw {

FileDataSource::FileDataSource(const char* tables_path, const char* calibration_path,
                               RigCalibration* rig)
    : tables_path_(tables_path), calibration_path_(calibration_path), rig_(rig) {}

FileDataSource::FileDataSource(const char* tables_path, const char* calibration_path,
                               const StereoCalibration* fallback_calibration)
    : tables_path_(tables_path),
      calibration_path_(calibration_path),
      fallback_(fallback_calibration) {}

Status FileDataSource::CheckPinned(const char* what, uint32_t crc32, uint32_t pinned,
                                   const char* key) {
  if (pinned == 0 || crc32 == pinned) return Status::Ok();
  return Status::Error(StatusCode::kFailedPrecondition,
                       "%s carry CRC-32 %08x, not the %08x that %s pins: another model set than "
                       "the one configured",
                       what, crc32, pinned, key);
}

Result<TableView> FileDataSource::LoadTable() {
  tables_crc32_ = 0;
  Result<TableView> table = OpenTable();
  if (!table.ok()) return table;
  const bool builtin = std::strcmp(tables_path_, "builtin") == 0;
  // The file mapped for the tables, or (a set of colour parts alone maps none) read for it.
  uint32_t crc32 = 0;
  if (builtin) {
    crc32 = BlobHeaderCrc32(DefaultTableBlob(), DefaultTableBlobSize());
  } else if (table_.model_count() > 0) {
    crc32 = mapped_.file_crc32();
  } else {
    SH_ASSIGN_OR_RETURN(crc32, FileBlobCrc32(tables_path_));
  }
  char what[kConfigPathMax + 16];
  std::snprintf(what, sizeof(what), builtin ? "the built-in tables" : "tables '%s'", tables_path_);
  const Status pinned = CheckPinned(what, crc32, pinned_tables_crc32_, "tables_crc32");
  if (!pinned.ok()) {
    table_ = TableView();
    return pinned;
  }
  tables_crc32_ = crc32;
  return table_;
}

Result<TableView> FileDataSource::OpenTable() {
  // Whatever happens below, the previous view may point into a mapping about to be replaced.
  table_ = TableView();
  const bool builtin = std::strcmp(tables_path_, "builtin") == 0;
  const void* blob = nullptr;
  size_t size = 0;
  if (builtin) {
    blob = DefaultTableBlob();
    size = DefaultTableBlobSize();
  } else {
    mapped_.Close();
    // A model set of colour parts alone has no polyhedra: no hash tables, not the built-in ones.
    const Result<uint32_t> kinds = FileBlobKinds(tables_path_);
    if (kinds.ok() && (*kinds & KindBit(SectionKind::kHash3d)) == 0 &&
        (*kinds & KindBit(SectionKind::kShapeViews)) != 0) {
      return table_;
    }
    SH_RETURN_IF_ERROR(mapped_.Open(tables_path_));
    if (!corrupt_tables_) {
      table_ = mapped_.view();
      return table_;
    }
    blob = mapped_.blob();  // the hash tables: the whole file, or the model set's HASH3D section
    size = mapped_.size();
  }
  if (corrupt_tables_) {
    // A damaged copy: one flipped byte in the middle of the payload.
    corrupt_copy_.reset(new uint64_t[(size + 7) / 8]);
    std::memcpy(corrupt_copy_.get(), blob, size);
    reinterpret_cast<uint8_t*>(corrupt_copy_.get())[size / 2] ^= 0x5A;
    blob = corrupt_copy_.get();
  }
  Result<TableView> view = TableView::Open(blob, size);
  if (!view.ok()) {
    return view.status().WithContext("%s tables", builtin ? "built-in" : tables_path_);
  }
  table_ = *view;
  return table_;
}

Result<FeatureDbView> FileDataSource::LoadFeatures() {
  // The previous view points into the mapping about to be replaced.
  mapped_features_.Close();
  features_crc32_ = 0;
  if (features_path_[0] != '\0') {
    SH_RETURN_IF_ERROR(mapped_features_.Open(features_path_));
    const uint32_t crc32 = mapped_features_.file_crc32();
    char what[kConfigPathMax + 16];
    std::snprintf(what, sizeof(what), "features '%s'", features_path_);
    const Status pinned = CheckPinned(what, crc32, pinned_features_crc32_, "features_crc32");
    if (!pinned.ok()) {
      mapped_features_.Close();
      return pinned;
    }
    features_crc32_ = crc32;
    return mapped_features_.view();
  }
  // Without `features`, a model set given as `tables` supplies its TEXTURE_FEATURES section. A
  // set that does not open is the tables' fault (LoadTable reports it), not a second one.
  if (!TablesHoldPrintedModels()) return FeatureDbView();
  SH_RETURN_IF_ERROR(mapped_features_.Open(tables_path_));
  return mapped_features_.view();
}

Result<ShapeViewsView> FileDataSource::LoadShapeViews() {
  mapped_views_.Close();  // the previous view points into it
  if (std::strcmp(tables_path_, "builtin") == 0) return ShapeViewsView();
  const Result<uint32_t> kinds = FileBlobKinds(tables_path_);
  // A set that does not open is the tables' fault (LoadTable reports it), not a second one.
  if (!kinds.ok() || (*kinds & KindBit(SectionKind::kShapeViews)) == 0) return ShapeViewsView();
  if (corrupt_tables_) {
    return Status::Error(StatusCode::kDataLoss, "%s: view database damaged (injected)",
                         tables_path_);
  }
  SH_RETURN_IF_ERROR(mapped_views_.Open(tables_path_));
  return mapped_views_.view();
}

bool FileDataSource::TablesHoldPrintedModels() const {
  if (std::strcmp(tables_path_, "builtin") == 0) return false;
  const Result<uint32_t> kinds = FileBlobKinds(tables_path_);
  return kinds.ok() && (*kinds & KindBit(SectionKind::kTextureFeatures)) != 0;
}

Result<StereoCalibration> FileDataSource::LoadCalibration() {
  if (missing_calibration_) {
    return Status::Error(StatusCode::kNotFound, "calibration missing (injected)");
  }
  if (calibration_path_[0] == '\0') {
    if (rig_ != nullptr) return rig_->Calibration();
    if (fallback_ == nullptr) {
      return Status::Error(StatusCode::kNotFound, "no calibration file configured");
    }
    return *fallback_;
  }
  static char text[kMaxCalibrationYamlBytes];
  size_t n = 0;
  SH_RETURN_IF_ERROR(ReadInputFile(calibration_path_, "calibration", text, sizeof(text), &n));
  Result<StereoCalibration> calib = ParseCalibrationYaml(text, n);
  if (!calib.ok()) {
    return calib.status().WithContext("%s", calibration_path_);
  }
  // A sensor larger than the pipeline's frames is captured binned (the camera's binned mode, its
  // ISP or DirectoryCamera): the frames' calibration is the file's, binned alike.
  Result<StereoCalibration> frames = FrameCalibration(*calib);
  if (!frames.ok()) return frames.status().WithContext("%s", calibration_path_);
  return frames;
}

}  // namespace sh::fw
