// What the core reports as wrong: the fault causes and warnings it holds as bits (each an error
// condition of the CANopen error register), and the EMCY detail values that say which data or
// which camera failed (docs/can-protocol.md, EMCY).
#pragma once

#include <cstdint>

namespace sh::fw {

// EMCY detail values of the data-set code (0x6300) and the sensor code (0x7300).
inline constexpr uint32_t kDetailTables = 1;
inline constexpr uint32_t kDetailCalibration = 2;
inline constexpr uint32_t kDetailCalibrationMismatch = 3;  // image size differs from calibration
inline constexpr uint32_t kDetailRecognitionInit = 4;
inline constexpr uint32_t kDetailFeatures = 5;  // feature database (`features`) or model count
// The cell's geometry: the table pose (`table_file`) or the hand-eye file (`handeye`) could not
// be used, or the output frame's transform is unknown (CoreConfig::cell_geometry).
inline constexpr uint32_t kDetailCellGeometry = 6;
inline constexpr uint32_t kSensorCaptureFailed = 1u << 24;   // | StatusCode << 16 | timeouts
inline constexpr uint32_t kSensorUnpairedFrames = 2u << 24;  // | unpaired drops in this capture
inline constexpr uint32_t kSensorStartFailed = 3u << 24;     // | StatusCode << 16
// One camera silent, recognition continues from the other: | failed side (0 left, 1 right)
// << 16 | timeouts.
inline constexpr uint32_t kSensorOneCamera = 4u << 24;

// Fault causes (bits); the fault state holds while any is set. Each is also an error condition
// of the CANopen error register, as are the warnings, which leave the state alone.
enum FaultBits : uint32_t {
  kFaultTables = 1u << 0,
  kFaultCalibration = 1u << 1,
  kFaultCamera = 1u << 2,
  kFaultCanBusOff = 1u << 3,
  kFaultCanTxDropped = 1u << 4,
  kFaultRecognition = 1u << 5,
  // Read at boot only (CoreConfig::cell_geometry): clear-fault cannot repair it, a restart can.
  kFaultCellGeometry = 1u << 6,
};
enum WarningBits : uint32_t {
  kWarningCanErrorPassive = 1u << 16,
  kWarningRecording = 1u << 17,  // record_dir: pairs cannot be written (full disk)
  kWarningOneCamera = 1u << 18,  // one camera failed: monocular results from the other
};

}  // namespace sh::fw
