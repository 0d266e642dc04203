// The firmware's data: model tables (linked in, a mapped file, or the HASH3D section of a model
// set; none for a set of colour parts alone), the colour parts' view database (the model set's
// SHAPE_VIEWS section; optional), the printed models' feature database (a mapped file, or the
// model set's TEXTURE_FEATURES section; optional) and the stereo calibration (YAML file, or the
// simulator rig). Reloaded when a data fault is cleared, so a file fixed on
// the board is picked up without a restart.
#pragma once

#include <cstdint>
#include <memory>

#include "firmware/firmware_core.hpp"
#include "tables/feature_db_view.hpp"
#include "tables/shape_views_file.hpp"
#include "tables/table_file.hpp"

namespace sh::fw {

// A calibration that is not read from a file: the simulator's rig, known once its world is
// built (which can fail, and succeed at a later try).
class RigCalibration {
 public:
  virtual ~RigCalibration() = default;
  virtual Result<StereoCalibration> Calibration() = 0;
};

class FileDataSource final : public DataSource {
 public:
  // tables_path: "builtin", a model set or a table blob file. calibration_path: a YAML file, or ""
  // to use the rig's calibration (nullptr = none, which is a missing calibration).
  FileDataSource(const char* tables_path, const char* calibration_path, RigCalibration* rig);
  // The same with a fixed calibration in place of the rig (nullptr = none).
  FileDataSource(const char* tables_path, const char* calibration_path,
                 const StereoCalibration* fallback_calibration);

  Result<TableView> LoadTable() override;
  // The calibration of the camera's frames: a file calibrated at a sensor size larger than
  // kMaxImageWidth x kMaxImageHeight is binned by BinFactorFor(), as the frames are.
  Result<StereoCalibration> LoadCalibration() override;
  Result<FeatureDbView> LoadFeatures() override;
  // The SHAPE_VIEWS section of the model set given as tables, or an empty view.
  Result<ShapeViewsView> LoadShapeViews() override;

  // The feature database file (`features`); "" = the TEXTURE_FEATURES section of the model set
  // given as tables, if it has one, else no printed models (the default).
  void SetFeaturesPath(const char* path) { features_path_ = path; }
  // Whether the tables file is a model set that opens and holds printed models (for sizing the
  // texture path's buffers at boot).
  bool TablesHoldPrintedModels() const;

  // The CRC-32s the tables and the features file must carry (tables_crc32, features_crc32 of the
  // configuration; 0 = any): loading other data is a data fault naming both values.
  void PinIdentity(uint32_t tables_crc32, uint32_t features_crc32) {
    pinned_tables_crc32_ = tables_crc32;
    pinned_features_crc32_ = features_crc32;
  }
  // The identity (BlobHeaderCrc32) of the tables and of the features file as last loaded: 0
  // before a load succeeded, and for features that come from the tables' model set.
  uint32_t tables_crc32() const { return tables_crc32_; }
  uint32_t features_crc32() const { return features_crc32_; }

  // Fault injection (simulator and tests): the next loads see a copy of the tables with one
  // payload byte flipped, or no calibration.
  void InjectCorruptTables(bool corrupt) { corrupt_tables_ = corrupt; }
  void InjectMissingCalibration(bool missing) { missing_calibration_ = missing; }

  // The table of the last load if it succeeded, else an empty view (valid while this object
  // lives and until the next load).
  const TableView& table() const { return table_; }

 private:
  Result<TableView> OpenTable();
  // The identity of what was just loaded checked against its pin; `key` names the pin.
  static Status CheckPinned(const char* what, uint32_t crc32, uint32_t pinned, const char* key);

  const char* tables_path_;
  const char* calibration_path_;
  RigCalibration* rig_ = nullptr;
  const StereoCalibration* fallback_ = nullptr;
  bool corrupt_tables_ = false;
  bool missing_calibration_ = false;
  const char* features_path_ = "";
  uint32_t pinned_tables_crc32_ = 0;
  uint32_t pinned_features_crc32_ = 0;
  uint32_t tables_crc32_ = 0;
  uint32_t features_crc32_ = 0;
  MappedTable mapped_;
  MappedFeatureDb mapped_features_;
  MappedShapeViews mapped_views_;
  std::unique_ptr<uint64_t[]> corrupt_copy_;  // 8-byte aligned as TableView requires
  TableView table_;
};

}  // namespace sh::fw
