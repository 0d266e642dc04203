#include "hal/linux/libcamera_adapter.hpp"

#include <libcamera/camera_manager.h>
#include <libcamera/color_space.h>
#include <libcamera/control_ids.h>

namespace sh::hal::libcamera_adapter {

std::unique_ptr<libcamera::CameraConfiguration> GenerateConfiguration(libcamera::Camera& camera,
                                                                      libcamera::StreamRole role) {
  // 0.0.x: const StreamRoles& (std::vector). From 0.1: Span<const StreamRole>, call with {role}.
  const libcamera::StreamRoles roles{role};
  return camera.generateConfiguration(roles);
}

int PlaneFd(const libcamera::FrameBuffer::Plane& plane) {
  // 0.0.x: SharedFD::get(). Before 0.0.1: FileDescriptor::fd().
  return plane.fd.get();
}

bool SensorTimestampNs(libcamera::Request& request, const libcamera::FrameBuffer& buffer,
                       int64_t* timestamp_ns) {
  // 0.0.1+: std::optional<int64_t>. Before: the value itself (0 when absent). Request::metadata()
  // has no const overload in 0.0.x, hence the non-const request.
  const std::optional<int64_t> sensor =
      request.metadata().get(libcamera::controls::SensorTimestamp);
  if (sensor.has_value() && *sensor > 0) {
    *timestamp_ns = *sensor;
    return true;
  }
  // FrameMetadata::timestamp is the same clock on V4L2 pipelines (end of exposure/readout there),
  // good enough for pairing two identical sensors.
  const uint64_t from_buffer = buffer.metadata().timestamp;
  if (from_buffer == 0) return false;
  *timestamp_ns = static_cast<int64_t>(from_buffer);
  return true;
}

bool RequestWasCancelled(const libcamera::Request& request) {
  return request.status() == libcamera::Request::RequestCancelled;
}

bool BufferCompletedOk(const libcamera::FrameBuffer& buffer) {
  return buffer.metadata().status == libcamera::FrameMetadata::FrameSuccess;
}

void ReuseRequest(libcamera::Request* request) { request->reuse(libcamera::Request::ReuseBuffers); }

void RequestSycc(libcamera::StreamConfiguration* config) {
  config->colorSpace = libcamera::ColorSpace::Sycc;
}

void StreamYcbcr(const libcamera::StreamConfiguration& config, YcbcrEncoding* encoding,
                 YcbcrRange* range) {
  *encoding = YcbcrEncoding::kRec601;
  *range = YcbcrRange::kFull;
  if (!config.colorSpace) return;
  const libcamera::ColorSpace& cs = *config.colorSpace;
  *encoding =
      cs.ycbcrEncoding == libcamera::ColorSpace::YcbcrEncoding::Rec601 ? YcbcrEncoding::kRec601
      : cs.ycbcrEncoding == libcamera::ColorSpace::YcbcrEncoding::None ? YcbcrEncoding::kRec601
                                                                       : YcbcrEncoding::kRec709;
  *range =
      cs.range == libcamera::ColorSpace::Range::Limited ? YcbcrRange::kLimited : YcbcrRange::kFull;
}

const std::string& LibraryVersion() { return libcamera::CameraManager::version(); }

}  // namespace sh::hal::libcamera_adapter
