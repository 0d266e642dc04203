// A board: the devices the firmware runs on, built from its configuration. Each program has one,
// in one wiring file: firmware/board_linux.cpp (stereohash-fw: SocketCAN, libgpiod, libcamera)
// and firmware/board_sim.cpp (stereohash-fw-sim: the simulated bus with its socketcand server,
// GPIO, the simulated world's cameras or recorded pairs, ground-truth recognition, the demo
// PLC). Everything else of a run (options, configuration, node id, data, table pose, output
// frame, recognition, the core, systemd, shutdown) is firmware_main.cpp, the same for both.
#pragma once

#include <cstdio>

#include "firmware/canopen/od_table.hpp"
#include "firmware/data_source.hpp"
#include "firmware/firmware_core.hpp"
#include "firmware/fw_config.hpp"
#include "firmware/recognition.hpp"
#include "hal/camera.hpp"
#include "hal/can.hpp"
#include "hal/gpio.hpp"
#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::fw {

struct BoardDevices {
  hal::CanBus* can = nullptr;
  hal::Gpio* gpio = nullptr;  // null: no hardware trigger, no outputs
  hal::StereoCamera* camera = nullptr;
};

class Board {
 public:
  virtual ~Board() = default;

  // The program's name, the `backend` value of configuration files written for it, and its
  // hardware version (0x1009).
  virtual const char* program() const = 0;
  virtual Backend backend() const = 0;
  virtual const char* hardware_version() const = 0;
  // The configuration before any file.
  virtual FwConfig Defaults() const = 0;
  // Whether the program runs without --config (the simulator has built-in defaults).
  virtual bool NeedsConfigFile() const { return true; }

  // Options of this program beyond --config, --run-seconds, --help and --config-keys-markdown:
  // returns how many arguments it took at argv[i] (0: not an option of this board, -1: refused,
  // with the reason printed).
  virtual int ParseOption(int argc, char** argv, int i) { return 0; }
  virtual void PrintOptions(std::FILE* out) const {}
  // Last changes after the file was read (simulator: demo mode, background preset, a replayed
  // set's calibration and table pose); validated again afterwards.
  virtual Status AdjustConfig(FwConfig* config) const { return Status::Ok(); }

  // Builds the CAN bus, GPIO and cameras (boot only; may allocate). No receive filter: LSS may
  // give the node another id at run time, and the core takes only the identifiers of its
  // current id (NMT, LSS, RPDOs, SDO) from what arrives.
  virtual Status OpenDevices(const FwConfig& config, BoardDevices* devices) = 0;
  // The rig's calibration when the configuration names none (the simulator's, known once its
  // world is built), or nullptr (a missing one).
  virtual RigCalibration* BuiltinCalibration() { return nullptr; }
  // The table frame in the left camera when the configuration gives none (the simulator's
  // rendered rig), or nullptr. It stays at this address and may be known only once the board's
  // world is built (*known_now false until then): recognition reads it again at each init.
  virtual const RigidTransform* DefaultTablePose(bool* known_now) const { return nullptr; }
  // Recognition other than the pipeline (the simulator's ground truth), or nullptr.
  virtual Recognition* OtherRecognition(const FwConfig& config) { return nullptr; }
  // Where the core's reports go besides the systemd watchdog (simulator stdout), or nullptr.
  virtual CoreObserver* Observer(const FwConfig& config, canopen::OutputFrame output_frame) {
    return nullptr;
  }

  // Just before the core starts (data source built), and right after it started.
  virtual Status BeforeStart(const FwConfig& config, FileDataSource* data) { return Status::Ok(); }
  virtual void AfterStart(const FwConfig& config, const FirmwareCore& core,
                          const FileDataSource& data) {}
  // After the core stopped.
  virtual void Stop() {}
};

// Runs the firmware on `board` until SIGTERM/SIGINT or --run-seconds: the whole program.
int FirmwareMain(int argc, char** argv, Board* board);
// True once SIGTERM or SIGINT arrived (for waits in a board's boot steps).
bool StopRequested();

}  // namespace sh::fw
