// The vision board (stereohash-fw): CAN through SocketCAN, the trigger input and the ready, busy
// and strobe outputs through libgpiod, the two cameras through libcamera. Nothing of the
// simulator is linked into this program (the board_program_has_no_simulator test checks its
// symbols).
#include <cstdio>
#include <cstring>
#include <memory>

#include "firmware/board.hpp"
#include "hal/linux/socketcan_bus.hpp"
#ifdef STEREOHASH_FW_HAVE_LIBCAMERA
#include "hal/linux/libcamera_camera.hpp"
#endif
#ifdef STEREOHASH_FW_HAVE_GPIOD
#include "hal/linux/gpiod_gpio.hpp"
#endif

namespace sh::fw {
namespace {

class LinuxBoard final : public Board {
 public:
  const char* program() const override { return "stereohash-fw"; }
  Backend backend() const override { return Backend::kLinux; }
  const char* hardware_version() const override { return "stereohash vision board"; }
  FwConfig Defaults() const override { return FwConfig(); }

  int ParseOption(int argc, char** argv, int i) override {
    if (!std::strcmp(argv[i], "--sim") || !std::strcmp(argv[i], "--demo")) {
      std::fprintf(stderr,
                   "stereohash-fw: %s: the simulator is its own program, stereohash-fw-sim\n",
                   argv[i]);
      return -1;
    }
    return 0;
  }

  Status OpenDevices(const FwConfig& config, BoardDevices* devices) override {
    hal::SocketCanConfig sc;
    sc.interface = config.can_interface;
    SH_RETURN_IF_ERROR(can_.Open(sc).WithContext("CAN"));
    devices->can = &can_;
    SH_RETURN_IF_ERROR(OpenCamera(config, devices));
    return OpenGpio(config, devices);
  }

 private:
  Status OpenCamera(const FwConfig& config, BoardDevices* devices) {
#ifdef STEREOHASH_FW_HAVE_LIBCAMERA
    hal::LibcameraStereoConfig lc;
    lc.left_id = config.camera_left_id;
    lc.right_id = config.camera_right_id;
    lc.left_index = config.camera_left_index;
    lc.right_index = config.camera_right_index;
    lc.width = config.camera_width;
    lc.height = config.camera_height;
    camera_ = std::make_unique<hal::LibcameraStereoCamera>(lc);
    devices->camera = camera_.get();
    return Status::Ok();
#else
    return Status::Error(StatusCode::kUnimplemented, "camera: this build has no libcamera backend");
#endif
  }

  // GPIO only when a line is wired: a board triggered over CAN alone needs no GPIO chip.
  Status OpenGpio(const FwConfig& config, BoardDevices* devices) {
    const bool wired = config.gpio_trigger_line >= 0 || config.gpio_ready_line >= 0 ||
                       config.gpio_busy_line >= 0 || config.gpio_strobe_line >= 0;
    if (!wired) return Status::Ok();
#ifdef STEREOHASH_FW_HAVE_GPIOD
    hal::GpiodConfig gc;
    gc.chip = config.gpio_chip;
    gc.trigger_line = config.gpio_trigger_line;
    gc.ready_line = config.gpio_ready_line;
    gc.busy_line = config.gpio_busy_line;
    gc.strobe_line = config.gpio_strobe_line;
    gc.outputs_active_low = config.gpio_outputs_active_low;
    gc.trigger_active_low = config.gpio_trigger_active_low;
    SH_RETURN_IF_ERROR(gpio_.Open(gc).WithContext("GPIO"));
    devices->gpio = &gpio_;
    return Status::Ok();
#else
    return Status::Error(StatusCode::kUnimplemented,
                         "GPIO: lines configured but this build has no libgpiod");
#endif
  }

  hal::SocketCanBus can_;
#ifdef STEREOHASH_FW_HAVE_LIBCAMERA
  std::unique_ptr<hal::LibcameraStereoCamera> camera_;
#endif
#ifdef STEREOHASH_FW_HAVE_GPIOD
  hal::GpiodGpio gpio_;
#endif
};

}  // namespace
}  // namespace sh::fw

int main(int argc, char** argv) {
  static sh::fw::LinuxBoard board;
  return sh::fw::FirmwareMain(argc, argv, &board);
}
