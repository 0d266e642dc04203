// The page's WebTarget over the running firmware: the core, its recorder, the CAN bus and the
// cameras.
#pragma once

#include "firmware/firmware_core.hpp"
#include "firmware/recorder.hpp"
#include "firmware/web/web_target.hpp"
#include "hal/camera.hpp"
#include "hal/can.hpp"

namespace sh::fw::web {

class CoreTarget final : public WebTarget {
 public:
  // `recorder` may be null (no record_dir).
  CoreTarget(FirmwareCore* core, const Recorder* recorder, const hal::CanBus* can,
             const hal::StereoCamera* camera)
      : core_(core), recorder_(recorder), can_(can), camera_(camera) {}

  WebHealth Health() const override;
  Status Trigger() override { return core_->RequestTrigger(); }
  void SetFreeRun(uint16_t rate_dhz) override { core_->SetFreeRunRate(rate_dhz); }
  Status RecordNext(int pairs) override;
  void ClearFault() override { core_->RequestClearFault(); }
  Result<bool> ApplySetting(ConfigKeyId key, const FwConfig& config) override;

 private:
  FirmwareCore* core_;
  const Recorder* recorder_;
  const hal::CanBus* can_;
  const hal::StereoCamera* camera_;
};

}  // namespace sh::fw::web
