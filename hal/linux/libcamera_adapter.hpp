// The libcamera calls whose signatures changed after 0.0.x, in one place.
//
// Written against libcamera 0.0.3 (Debian 12). Known later changes this file absorbs:
// - Camera::generateConfiguration() takes Span<const StreamRole> from 0.1 (a StreamRoles vector
//   before);
// - FrameBuffer::Plane::fd is a SharedFD (0.0.x) and a FileDescriptor before 0.0.1;
// - ControlList::get() returns std::optional<T> from 0.0.1 (T before);
// - CameraConfiguration::transform became orientation in 0.2 (not used here).
// Porting to another libcamera version should only touch libcamera_adapter.cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <libcamera/camera.h>
#include <libcamera/framebuffer.h>
#include <libcamera/request.h>
#include <libcamera/stream.h>

#include "recog/image/frame.hpp"

namespace sh::hal::libcamera_adapter {

std::unique_ptr<libcamera::CameraConfiguration> GenerateConfiguration(libcamera::Camera& camera,
                                                                      libcamera::StreamRole role);

// The dmabuf file descriptor of a buffer plane (-1 if invalid).
int PlaneFd(const libcamera::FrameBuffer::Plane& plane);

// controls::SensorTimestamp of a completed request (start of exposure, ns), falling back to the
// buffer's own timestamp when the pipeline handler does not report it. False if neither is set.
bool SensorTimestampNs(libcamera::Request& request, const libcamera::FrameBuffer& buffer,
                       int64_t* timestamp_ns);

bool RequestWasCancelled(const libcamera::Request& request);
bool BufferCompletedOk(const libcamera::FrameBuffer& buffer);

// Makes a completed request ready to be queued again with the same buffer.
void ReuseRequest(libcamera::Request* request);

// Asks for BT.601 full-range Y'CbCr (sYCC, what the colour path's thresholds assume) on a YUV
// stream; the pipeline may replace it at validate().
void RequestSycc(libcamera::StreamConfiguration* config);
// The Y'CbCr encoding and range a validated stream delivers: its colorSpace when set (Rec2020 is
// read as Rec709, the nearest the frame views know), else BT.601 full range.
void StreamYcbcr(const libcamera::StreamConfiguration& config, YcbcrEncoding* encoding,
                 YcbcrRange* range);

// libcamera's own version string, for logs and error messages.
const std::string& LibraryVersion();

}  // namespace sh::hal::libcamera_adapter
