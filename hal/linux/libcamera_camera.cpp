#include "hal/linux/libcamera_camera.hpp"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <iterator>
#include <new>
#include <vector>

#include <sys/mman.h>
#include <unistd.h>

#include <libcamera/camera.h>
#include <libcamera/camera_manager.h>
#include <libcamera/formats.h>
#include <libcamera/framebuffer_allocator.h>
#include <libcamera/request.h>
#include <libcamera/stream.h>

#include "hal/linux/libcamera_adapter.hpp"
#include "recog/image/binning.hpp"

namespace sh::hal {

namespace lc = libcamera;

namespace {

struct FormatChoice {
  lc::PixelFormat pixel_format;
  FrameFormat frame_format = FrameFormat::kGray8;  // how the frames are handed out
};

// Preference orders (see the header). Grey: formats whose first plane is 8-bit grey, delivered
// as that plane alone. Colour: Y'CbCr first (the grey path keeps its zero-copy Y plane), then
// 24-bit RGB (libcamera's BGR888 is R, G, B in memory, DRM's naming), then a grey sensor's R8.
const FormatChoice kGreyFormats[] = {{lc::formats::R8, FrameFormat::kGray8},
                                     {lc::formats::NV12, FrameFormat::kGray8},
                                     {lc::formats::YUV420, FrameFormat::kGray8}};
const FormatChoice kColourFormats[] = {{lc::formats::NV12, FrameFormat::kNv12},
                                       {lc::formats::YUV420, FrameFormat::kYuv420},
                                       {lc::formats::BGR888, FrameFormat::kRgb888},
                                       {lc::formats::R8, FrameFormat::kGray8}};

lc::StreamRole ToStreamRole(LibcameraRole role) {
  switch (role) {
    case LibcameraRole::kViewfinder:
      return lc::StreamRole::Viewfinder;
    case LibcameraRole::kRaw:
      return lc::StreamRole::Raw;
    case LibcameraRole::kVideoRecording:
      break;
  }
  return lc::StreamRole::VideoRecording;
}

struct Mapping {
  void* base = MAP_FAILED;
  size_t length = 0;
};

// Planes a buffer is mapped in: Y (or RGB), and the chroma plane(s) of Y'CbCr formats.
constexpr int kMaxPlanes = 3;

}  // namespace

struct LibcameraStereoCamera::Impl {
  // One camera of the pair and everything it owns while started.
  struct Side {
    Impl* owner = nullptr;
    StereoSide side = StereoSide::kLeft;
    std::shared_ptr<lc::Camera> camera;
    bool acquired = false;
    bool configured = false;
    bool started = false;
    std::unique_ptr<lc::CameraConfiguration> config;
    lc::Stream* stream = nullptr;
    std::unique_ptr<lc::FrameBufferAllocator> allocator;
    std::vector<std::unique_ptr<lc::Request>> requests;
    Mapping mappings[kMaxLibcameraBuffers][kMaxPlanes];
    ConstGrayView views[kMaxLibcameraBuffers];  // grey: in place, or `luma` of an RGB frame
    FrameView frames[kMaxLibcameraBuffers];     // the delivered format
    // RGB888 or software binning: one grey image per buffer, converted (binned) on libcamera's
    // thread when the frame completes (allocated at Start).
    std::unique_ptr<uint8_t[]> luma;
    // Software binning: the mapped frames at the sensor's size, and for RGB888 the binned RGB
    // image of each buffer.
    FrameView sensor_frames[kMaxLibcameraBuffers];
    std::unique_ptr<Rgb8[]> binned_rgb;
    unsigned buffer_count = 0;

    const char* name() const { return StereoSideName(side); }
    void OnRequestCompleted(lc::Request* request) { owner->OnRequestCompleted(*this, request); }
    void OnDisconnected() { owner->OnDisconnected(*this); }
  };

  explicit Impl(const LibcameraStereoConfig& c) : config(c) {
    sides[0].owner = this;
    sides[0].side = StereoSide::kLeft;
    sides[1].owner = this;
    sides[1].side = StereoSide::kRight;
  }

  Status Start();
  void Teardown();
  Status SelectCameras();
  Status Configure();
  Status ConfigureFirst(Side& s, const lc::Size& size);
  bool Used(const Side& s) const {
    return mode == CaptureMode::kStereo ||
           (mode == CaptureMode::kLeftOnly) == (s.side == StereoSide::kLeft);
  }
  Status MapBuffers(Side& s);
  Status AllocateConverted(Side& s, int width, int height);
  void HandOutBinned(Side& s, unsigned i, int width, int height);
  void Convert(Side& s, uint32_t id);
  Status StartStreaming();
  void Requeue(StereoSide side, uint32_t buffer_id);
  void RequeueAll(const Vector<RecycledFrame>& recycled);
  void OnRequestCompleted(Side& s, lc::Request* request);
  void OnDisconnected(Side& s);

  LibcameraStereoConfig config;
  CaptureMode mode = CaptureMode::kStereo;         // of the next Start()
  bool colour_wanted = false;                      // of the next Start()
  FrameFormat frame_format = FrameFormat::kGray8;  // as the camera delivers it
  int software_bin = 1;                            // see LibcameraStreamInfo::software_bin
  YcbcrEncoding encoding = YcbcrEncoding::kRec601;
  YcbcrRange range = YcbcrRange::kFull;
  std::unique_ptr<lc::CameraManager> manager;
  bool manager_started = false;
  Side sides[2];
  StereoPairer pairer;
  std::atomic<bool> running{false};
  bool holding = false;
  FramePair held;
  LibcameraStreamInfo info;
  int cameras_found = 0;
};

Status LibcameraStereoCamera::Impl::Start() {
  SH_RETURN_IF_ERROR(pairer.Configure(config.pairing));
  pairer.SetMode(mode);
  manager = std::make_unique<lc::CameraManager>();
  const int ret = manager->start();
  if (ret != 0) {
    return Status::Error(StatusCode::kUnavailable, "libcamera %s CameraManager::start failed: %s",
                         libcamera_adapter::LibraryVersion().c_str(), std::strerror(-ret));
  }
  manager_started = true;
  SH_RETURN_IF_ERROR(SelectCameras());
  SH_RETURN_IF_ERROR(Configure());
  for (Side& s : sides) {
    if (Used(s)) SH_RETURN_IF_ERROR(MapBuffers(s));
  }
  return StartStreaming();
}

Status LibcameraStereoCamera::Impl::SelectCameras() {
  const std::vector<std::shared_ptr<lc::Camera>> cameras = manager->cameras();
  cameras_found = static_cast<int>(cameras.size());
  const size_t needed = mode == CaptureMode::kStereo ? 2 : 1;
  if (cameras.size() < needed) {
    return Status::Error(StatusCode::kNotFound, "libcamera found %zu cameras, need %zu",
                         cameras.size(), needed);
  }
  const std::string* ids[2] = {&config.left_id, &config.right_id};
  const int indices[2] = {config.left_index, config.right_index};
  for (int i = 0; i < 2; ++i) {
    Side& s = sides[i];
    if (!Used(s)) continue;
    if (!ids[i]->empty()) {
      s.camera = manager->get(*ids[i]);
      if (!s.camera) {
        return Status::Error(StatusCode::kNotFound, "no %s camera with id '%s' (%zu cameras)",
                             s.name(), ids[i]->c_str(), cameras.size());
      }
    } else {
      if (indices[i] < 0 || static_cast<size_t>(indices[i]) >= cameras.size()) {
        return Status::Error(StatusCode::kNotFound, "%s camera index %d outside 0..%zu", s.name(),
                             indices[i], cameras.size() - 1);
      }
      s.camera = cameras[static_cast<size_t>(indices[i])];
    }
  }
  if (mode == CaptureMode::kStereo && sides[0].camera == sides[1].camera) {
    return Status::Error(StatusCode::kInvalidArgument, "left and right select the same camera %s",
                         sides[0].camera->id().c_str());
  }
  for (Side& s : sides) {
    if (!Used(s)) continue;
    const int ret = s.camera->acquire();
    if (ret != 0) {
      return Status::Error(StatusCode::kUnavailable, "%s camera %s cannot be acquired: %s",
                           s.name(), s.camera->id().c_str(), std::strerror(-ret));
    }
    s.acquired = true;
  }
  info.left_id = sides[0].camera ? sides[0].camera->id() : std::string();
  info.right_id = sides[1].camera ? sides[1].camera->id() : std::string();
  return Status::Ok();
}

// Tries the formats in order (colour or grey, as asked) on the first camera used (the left one
// in stereo); the first format that validates without being replaced wins. Size adjustments by
// the camera are accepted (reported in stream_info()); `size` is what is asked for.
Status LibcameraStereoCamera::Impl::ConfigureFirst(Side& s, const lc::Size& size) {
  const FormatChoice* choices = colour_wanted ? kColourFormats : kGreyFormats;
  const size_t n_choices = colour_wanted ? std::size(kColourFormats) : std::size(kGreyFormats);
  for (size_t i = 0; i < n_choices; ++i) {
    const FormatChoice& choice = choices[i];
    std::unique_ptr<lc::CameraConfiguration> c =
        libcamera_adapter::GenerateConfiguration(*s.camera, ToStreamRole(config.role));
    if (!c || c->size() != 1) continue;
    lc::StreamConfiguration& sc = c->at(0);
    sc.pixelFormat = choice.pixel_format;
    sc.size = size;
    sc.bufferCount = kLibcameraBufferCount;
    const bool ycbcr =
        choice.frame_format == FrameFormat::kNv12 || choice.frame_format == FrameFormat::kYuv420;
    if (ycbcr) libcamera_adapter::RequestSycc(&sc);
    if (c->validate() == lc::CameraConfiguration::Invalid) continue;
    if (sc.pixelFormat != choice.pixel_format) continue;
    frame_format = choice.frame_format;
    libcamera_adapter::StreamYcbcr(sc, &encoding, &range);
    s.config = std::move(c);
    return Status::Ok();
  }
  return Status::Error(
      StatusCode::kFailedPrecondition, "%s camera %s offers none of %s for this role", s.name(),
      s.camera->id().c_str(), colour_wanted ? "NV12, YUV420, BGR888, R8" : "R8, NV12, YUV420");
}

Status LibcameraStereoCamera::Impl::Configure() {
  if (config.width <= 0 || config.height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "requested size %dx%d is empty",
                         config.width, config.height);
  }
  // A sensor larger than the pipeline's frames is asked for its binned size: the sensor's
  // binned mode or the ISP's scaler delivers it, as the calibration is binned.
  const Result<int> bin = BinFactorFor(config.width, config.height);
  if (!bin.ok()) return bin.status().WithContext("camera");
  Side& first = mode == CaptureMode::kRightOnly ? sides[1] : sides[0];
  const lc::Size frames(static_cast<unsigned>(BinnedSize(config.width, *bin)),
                        static_cast<unsigned>(BinnedSize(config.height, *bin)));
  SH_RETURN_IF_ERROR(ConfigureFirst(first, frames));
  software_bin = 1;
  if (*bin > 1 && (first.config->at(0).size.width > static_cast<unsigned>(kMaxImageWidth) ||
                   first.config->at(0).size.height > static_cast<unsigned>(kMaxImageHeight))) {
    // Neither a binned mode nor a scaler: the sensor's size, binned here as each frame completes.
    const lc::Size sensor(static_cast<unsigned>(config.width),
                          static_cast<unsigned>(config.height));
    SH_RETURN_IF_ERROR(ConfigureFirst(first, sensor));
    if (first.config->at(0).size != sensor) {
      return Status::Error(StatusCode::kFailedPrecondition,
                           "camera offers neither %ux%u nor the sensor's %ux%u (it settled on "
                           "%ux%u)",
                           frames.width, frames.height, sensor.width, sensor.height,
                           first.config->at(0).size.width, first.config->at(0).size.height);
    }
    software_bin = *bin;
  }
  const lc::StreamConfiguration left_sc = first.config->at(0);

  // The right camera must produce exactly what the left one settled on: stereo matching assumes
  // identical geometry and timing.
  Side& r = sides[1];
  if (mode == CaptureMode::kStereo) {
    r.config = libcamera_adapter::GenerateConfiguration(*r.camera, ToStreamRole(config.role));
    if (!r.config || r.config->size() != 1) {
      return Status::Error(StatusCode::kFailedPrecondition,
                           "right camera %s cannot generate a configuration for this role",
                           r.camera->id().c_str());
    }
    lc::StreamConfiguration& rsc = r.config->at(0);
    rsc.pixelFormat = left_sc.pixelFormat;
    rsc.size = left_sc.size;
    rsc.bufferCount = left_sc.bufferCount;
    rsc.colorSpace = left_sc.colorSpace;
    const lc::CameraConfiguration::Status rv = r.config->validate();
    if (rv == lc::CameraConfiguration::Invalid || rsc.pixelFormat != left_sc.pixelFormat ||
        rsc.size != left_sc.size || rsc.colorSpace != left_sc.colorSpace) {
      return Status::Error(
          StatusCode::kFailedPrecondition,
          "right camera cannot match left configuration %s %ux%u (offers %s %ux%u)",
          left_sc.pixelFormat.toString().c_str(), left_sc.size.width, left_sc.size.height,
          rsc.pixelFormat.toString().c_str(), rsc.size.width, rsc.size.height);
    }
  }
  const int delivered_width = BinnedSize(static_cast<int>(left_sc.size.width), software_bin);
  const int delivered_height = BinnedSize(static_cast<int>(left_sc.size.height), software_bin);
  if (delivered_width > kMaxImageWidth || delivered_height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "camera size %ux%u exceeds %dx%d",
                         left_sc.size.width, left_sc.size.height, kMaxImageWidth, kMaxImageHeight);
  }
  for (Side& s : sides) {
    if (!Used(s)) continue;
    const int ret = s.camera->configure(s.config.get());
    if (ret != 0) {
      return Status::Error(StatusCode::kUnavailable, "%s camera configure failed: %s", s.name(),
                           std::strerror(-ret));
    }
    s.configured = true;
    s.stream = s.config->at(0).stream();
  }
  const bool ycbcr = frame_format == FrameFormat::kNv12 || frame_format == FrameFormat::kYuv420;
  info.pixel_format = left_sc.pixelFormat.toString();
  info.format = software_bin > 1 && ycbcr ? FrameFormat::kGray8 : frame_format;
  info.encoding = encoding;
  info.range = range;
  info.width = delivered_width;
  info.height = delivered_height;
  info.stride = software_bin > 1 ? delivered_width : static_cast<int>(left_sc.stride);
  info.software_bin = software_bin;
  return Status::Ok();
}

// Maps [offset, offset + length) of a plane's dmabuf read-only (from offset 0 of the fd, so the
// mmap offset stays page aligned); returns the first byte, or null with errno set.
const uint8_t* MapRange(const lc::FrameBuffer::Plane& plane, size_t offset, Mapping* mapping) {
  const size_t length = offset + plane.length;
  void* base = mmap(nullptr, length, PROT_READ, MAP_SHARED, libcamera_adapter::PlaneFd(plane), 0);
  if (base == MAP_FAILED) return nullptr;
  *mapping = Mapping{base, length};
  return static_cast<const uint8_t*>(base) + offset;
}

// Allocates the buffers, maps the planes of each once (the Y or RGB plane, and for a colour
// Y'CbCr stream its chroma: a plane of its own, or following Y in a single-plane buffer), and
// builds one request per buffer (cookie = buffer index) that is reused for the whole session.
Status LibcameraStereoCamera::Impl::MapBuffers(Side& s) {
  s.allocator = std::make_unique<lc::FrameBufferAllocator>(s.camera);
  const int allocated = s.allocator->allocate(s.stream);
  if (allocated <= 0) {
    return Status::Error(StatusCode::kInternal, "%s camera buffer allocation failed: %s", s.name(),
                         std::strerror(allocated < 0 ? -allocated : ENOMEM));
  }
  const std::vector<std::unique_ptr<lc::FrameBuffer>>& buffers = s.allocator->buffers(s.stream);
  const lc::StreamConfiguration& sc = s.config->at(0);
  const int width = static_cast<int>(sc.size.width);
  const int height = static_cast<int>(sc.size.height);
  const int bytes_per_pixel = frame_format == FrameFormat::kRgb888 ? 3 : 1;
  const size_t stride = sc.stride != 0 ? sc.stride : size_t(sc.size.width) * bytes_per_pixel;
  const int cw = (width + 1) / 2, ch = (height + 1) / 2;
  // Chroma rows: NV12 interleaved pairs with the luma stride in bytes; I420 half the stride.
  const size_t chroma_stride = frame_format == FrameFormat::kNv12 ? stride : stride / 2;
  const size_t chroma_bytes = chroma_stride * size_t(ch);
  if (frame_format == FrameFormat::kRgb888 && stride % 3 != 0) {
    return Status::Error(StatusCode::kInternal, "%s camera RGB stride %zu is not whole pixels",
                         s.name(), stride);
  }
  s.buffer_count = static_cast<unsigned>(
      buffers.size() < kMaxLibcameraBuffers ? buffers.size() : kMaxLibcameraBuffers);
  info.buffers_per_camera = s.buffer_count;
  SH_RETURN_IF_ERROR(AllocateConverted(s, width, height));
  for (unsigned i = 0; i < s.buffer_count; ++i) {
    lc::FrameBuffer* buffer = buffers[i].get();
    const std::vector<lc::FrameBuffer::Plane>& planes = buffer->planes();
    if (planes.empty()) {
      return Status::Error(StatusCode::kInternal, "%s buffer %u has no planes", s.name(), i);
    }
    const lc::FrameBuffer::Plane& y = planes[0];
    const bool chroma_in_first = frame_format != FrameFormat::kGray8 &&
                                 frame_format != FrameFormat::kRgb888 && planes.size() == 1;
    const size_t needed =
        stride * static_cast<size_t>(height) +
        (chroma_in_first ? (frame_format == FrameFormat::kYuv420 ? 2 : 1) * chroma_bytes : 0);
    if (y.length < needed) {
      return Status::Error(StatusCode::kInternal, "%s buffer %u first plane has %u bytes, need %zu",
                           s.name(), i, y.length, needed);
    }
    const uint8_t* first = MapRange(y, y.offset, &s.mappings[i][0]);
    if (first == nullptr) {
      return Status::Error(StatusCode::kInternal, "%s buffer %u mmap failed: %s", s.name(), i,
                           std::strerror(errno));
    }
    // The chroma planes: in the first plane after Y, or planes 1 (and 2) of their own.
    const uint8_t* chroma[2] = {first + stride * size_t(height),
                                first + stride * size_t(height) + chroma_bytes};
    const int n_chroma = frame_format == FrameFormat::kNv12     ? 1
                         : frame_format == FrameFormat::kYuv420 ? 2
                                                                : 0;
    if (n_chroma > 0 && !chroma_in_first) {
      // Cb (and Cr) in the second plane, Cr in a third one or after Cb in the second.
      const bool own_cr = n_chroma == 2 && planes.size() >= 3;
      const size_t second_needed = chroma_bytes * (n_chroma == 2 && !own_cr ? 2 : 1);
      if (planes.size() < 2 || planes[1].length < second_needed ||
          (own_cr && planes[2].length < chroma_bytes)) {
        return Status::Error(StatusCode::kInternal, "%s buffer %u chroma planes missing or short",
                             s.name(), i);
      }
      chroma[0] = MapRange(planes[1], planes[1].offset, &s.mappings[i][1]);
      chroma[1] = chroma[0] == nullptr ? nullptr
                  : own_cr             ? MapRange(planes[2], planes[2].offset, &s.mappings[i][2])
                                       : chroma[0] + chroma_bytes;
      if (chroma[0] == nullptr || (n_chroma == 2 && chroma[1] == nullptr)) {
        return Status::Error(StatusCode::kInternal, "%s buffer %u chroma mmap failed: %s", s.name(),
                             i, std::strerror(errno));
      }
    }
    switch (frame_format) {
      case FrameFormat::kGray8:
        s.views[i] = ConstGrayView{first, width, height, static_cast<int>(stride)};
        s.frames[i] = FrameView::Gray(s.views[i]);
        break;
      case FrameFormat::kNv12:
        s.views[i] = ConstGrayView{first, width, height, static_cast<int>(stride)};
        s.frames[i] =
            FrameView::Nv12(s.views[i],
                            ImageView<const CbCr8>{reinterpret_cast<const CbCr8*>(chroma[0]), cw,
                                                   ch, static_cast<int>(chroma_stride / 2)},
                            encoding, range);
        break;
      case FrameFormat::kYuv420:
        s.views[i] = ConstGrayView{first, width, height, static_cast<int>(stride)};
        s.frames[i] = FrameView::Yuv420(
            s.views[i], ConstGrayView{chroma[0], cw, ch, static_cast<int>(chroma_stride)},
            ConstGrayView{chroma[1], cw, ch, static_cast<int>(chroma_stride)}, encoding, range);
        break;
      case FrameFormat::kRgb888:
        s.frames[i] = FrameView::Rgb(ImageView<const Rgb8>{
            reinterpret_cast<const Rgb8*>(first), width, height, static_cast<int>(stride / 3)});
        s.views[i] =
            ConstGrayView{s.luma.get() + size_t(width) * size_t(height) * i, width, height, width};
        break;
    }
    const Status frame_ok = CheckFrame(s.frames[i]);
    if (!frame_ok.ok()) return frame_ok.WithContext("%s buffer %u", s.name(), i);
    if (software_bin > 1) HandOutBinned(s, i, width, height);

    std::unique_ptr<lc::Request> request = s.camera->createRequest(i);
    if (!request) {
      return Status::Error(StatusCode::kInternal, "%s camera createRequest failed", s.name());
    }
    const int ret = request->addBuffer(s.stream, buffer);
    if (ret != 0) {
      return Status::Error(StatusCode::kInternal, "%s request addBuffer failed: %s", s.name(),
                           std::strerror(-ret));
    }
    s.requests.push_back(std::move(request));
  }
  return Status::Ok();
}

Status LibcameraStereoCamera::Impl::StartStreaming() {
  RecycleList recycled;
  pairer.Reset(recycled);
  holding = false;
  for (Side& s : sides) {
    if (!Used(s)) continue;
    s.camera->requestCompleted.connect(&s, &Side::OnRequestCompleted);
    s.camera->disconnected.connect(&s, &Side::OnDisconnected);
  }
  running = true;
  for (Side& s : sides) {
    if (!Used(s)) continue;
    const int ret = s.camera->start();
    if (ret != 0) {
      return Status::Error(StatusCode::kUnavailable, "%s camera %s start failed: %s", s.name(),
                           s.camera->id().c_str(), std::strerror(-ret));
    }
    s.started = true;
  }
  for (Side& s : sides) {
    if (!Used(s)) continue;
    for (std::unique_ptr<lc::Request>& request : s.requests) {
      const int ret = s.camera->queueRequest(request.get());
      if (ret != 0) {
        return Status::Error(StatusCode::kUnavailable, "%s camera queueRequest failed: %s",
                             s.name(), std::strerror(-ret));
      }
    }
  }
  return Status::Ok();
}

void LibcameraStereoCamera::Impl::Requeue(StereoSide side, uint32_t buffer_id) {
  Side& s = sides[static_cast<int>(side)];
  if (!running || buffer_id >= s.requests.size()) return;
  lc::Request* request = s.requests[buffer_id].get();
  libcamera_adapter::ReuseRequest(request);
  // queueRequest is thread-safe in libcamera; it fails only while stopping or disconnected.
  if (s.camera->queueRequest(request) != 0 && running) pairer.ReportError(side);
}

void LibcameraStereoCamera::Impl::RequeueAll(const Vector<RecycledFrame>& recycled) {
  for (const RecycledFrame& r : recycled) Requeue(r.side, r.frame.buffer_id);
}

// The images converted from each delivered frame: the grey image of an RGB frame, and with
// software binning the binned image (grey, and RGB for an RGB frame), one per buffer.
Status LibcameraStereoCamera::Impl::AllocateConverted(Side& s, int width, int height) {
  const size_t per_buffer =
      size_t(BinnedSize(width, software_bin)) * size_t(BinnedSize(height, software_bin));
  if (frame_format == FrameFormat::kRgb888 || software_bin > 1) {
    s.luma.reset(new (std::nothrow) uint8_t[per_buffer * s.buffer_count]);
    if (!s.luma) return Status::Error(StatusCode::kInternal, "%s grey buffers", s.name());
  }
  if (frame_format == FrameFormat::kRgb888 && software_bin > 1) {
    s.binned_rgb.reset(new (std::nothrow) Rgb8[per_buffer * s.buffer_count]);
    if (!s.binned_rgb) return Status::Error(StatusCode::kInternal, "%s binned buffers", s.name());
  }
  return Status::Ok();
}

// Software binning: buffer i's mapped frame becomes the source, and what is handed out is its
// binned image (grey; RGB for an RGB camera, whose grey is converted from the binned RGB).
void LibcameraStereoCamera::Impl::HandOutBinned(Side& s, unsigned i, int width, int height) {
  const int w = BinnedSize(width, software_bin), h = BinnedSize(height, software_bin);
  const size_t offset = size_t(w) * size_t(h) * i;
  s.sensor_frames[i] = s.frames[i];
  s.views[i] = ConstGrayView{s.luma.get() + offset, w, h, w};
  s.frames[i] = frame_format == FrameFormat::kRgb888
                    ? FrameView::Rgb(ImageView<const Rgb8>{s.binned_rgb.get() + offset, w, h, w})
                    : FrameView::Gray(s.views[i]);
}

// On libcamera's thread, into buffer `id`'s own images (no allocation; the conversions fail only
// on sizes, which MapBuffers set).
void LibcameraStereoCamera::Impl::Convert(Side& s, uint32_t id) {
  const ConstGrayView& v = s.views[id];
  const GrayView grey{const_cast<uint8_t*>(v.data), v.width, v.height, v.stride};
  if (software_bin > 1 && frame_format == FrameFormat::kRgb888) {
    const FrameView& binned = s.frames[id];
    (void)BinRgb(s.sensor_frames[id].rgb, software_bin,
                 ImageView<Rgb8>{const_cast<Rgb8*>(binned.rgb.data), binned.rgb.width,
                                 binned.rgb.height, binned.rgb.stride});
    (void)FrameToGray(binned, grey);
  } else if (software_bin > 1) {
    // The Y plane of every grey or Y'CbCr format.
    (void)BinGray(s.sensor_frames[id].luma, software_bin, grey);
  } else if (frame_format == FrameFormat::kRgb888) {
    (void)FrameToGray(s.frames[id], grey);
  }
}

// Runs on libcamera's thread.
void LibcameraStereoCamera::Impl::OnRequestCompleted(Side& s, lc::Request* request) {
  if (libcamera_adapter::RequestWasCancelled(*request) || !running) return;
  const uint32_t id = static_cast<uint32_t>(request->cookie());
  const lc::FrameBuffer* buffer = request->findBuffer(s.stream);
  int64_t t_ns = 0;
  if (buffer == nullptr || id >= s.buffer_count || !libcamera_adapter::BufferCompletedOk(*buffer) ||
      !libcamera_adapter::SensorTimestampNs(*request, *buffer, &t_ns)) {
    pairer.ReportError(s.side);
    Requeue(s.side, id);
    return;
  }
  Convert(s, id);
  TimestampedFrame frame;
  frame.view = s.views[id];
  frame.frame = s.frames[id];
  frame.timestamp_ns = t_ns;
  frame.sequence = buffer->metadata().sequence;
  frame.buffer_id = id;
  RecycleList recycled;
  pairer.Push(s.side, frame, recycled);
  RequeueAll(recycled);
}

void LibcameraStereoCamera::Impl::OnDisconnected(Side& s) {
  pairer.Close(Status::Error(StatusCode::kUnavailable, "%s camera %s disconnected", s.name(),
                             s.camera->id().c_str()));
}

// Undoes whatever part of Start() succeeded, in reverse order. Safe to call repeatedly.
void LibcameraStereoCamera::Impl::Teardown() {
  running = false;
  pairer.Close(Status::Error(StatusCode::kUnavailable, "stereo camera stopped"));
  for (Side& s : sides) {
    // stop() returns once every queued request has completed (cancelled ones included), so no
    // completion handler runs after this loop.
    if (s.started) s.camera->stop();
    s.started = false;
  }
  RecycleList recycled;
  pairer.Drain(recycled);  // buffers go back with the allocator below, nothing to requeue
  holding = false;
  for (Side& s : sides) {
    if (s.camera) {
      s.camera->requestCompleted.disconnect(&s);
      s.camera->disconnected.disconnect(&s);
    }
    s.requests.clear();
    for (unsigned i = 0; i < kMaxLibcameraBuffers; ++i) {
      for (Mapping& m : s.mappings[i]) {
        if (m.base != MAP_FAILED) munmap(m.base, m.length);
        m = Mapping{};
      }
      s.views[i] = ConstGrayView{};
      s.frames[i] = FrameView{};
    }
    s.luma.reset();
    s.buffer_count = 0;
    if (s.allocator && s.stream != nullptr) s.allocator->free(s.stream);
    s.allocator.reset();
    s.stream = nullptr;
    s.config.reset();
    s.configured = false;
    if (s.acquired) s.camera->release();
    s.acquired = false;
    s.camera.reset();
  }
  if (manager_started) manager->stop();
  manager_started = false;
  manager.reset();
}

LibcameraStereoCamera::LibcameraStereoCamera(const LibcameraStereoConfig& config)
    : impl_(std::make_unique<Impl>(config)) {}

LibcameraStereoCamera::~LibcameraStereoCamera() { (void)Stop(); }

Status LibcameraStereoCamera::Start() {
  if (impl_->manager) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "libcamera stereo camera already started");
  }
  const Status s = impl_->Start();
  if (!s.ok()) impl_->Teardown();
  return s;
}

Status LibcameraStereoCamera::Stop() {
  if (impl_->manager) impl_->Teardown();
  return Status::Ok();
}

Status LibcameraStereoCamera::Capture(StereoFrame* out, int timeout_ms) {
  if (out == nullptr) return Status::Error(StatusCode::kInvalidArgument, "Capture needs an output");
  if (!impl_->running) {
    return Status::Error(StatusCode::kFailedPrecondition, "libcamera stereo camera not started");
  }
  Release();
  FramePair pair;
  SH_RETURN_IF_ERROR(impl_->pairer.WaitPair(timeout_ms, &pair));
  impl_->held = pair;
  impl_->holding = true;
  *out = ToStereoFrame(pair);
  return Status::Ok();
}

void LibcameraStereoCamera::Release() {
  if (!impl_->holding) return;
  // The empty half of a one-side frame holds no buffer.
  if (impl_->held.left.view.data != nullptr) {
    impl_->Requeue(StereoSide::kLeft, impl_->held.left.buffer_id);
  }
  if (impl_->held.right.view.data != nullptr) {
    impl_->Requeue(StereoSide::kRight, impl_->held.right.buffer_id);
  }
  impl_->holding = false;
}

CameraStats LibcameraStereoCamera::stats() const { return impl_->pairer.stats(); }

Status LibcameraStereoCamera::SetCaptureMode(CaptureMode mode) {
  impl_->mode = mode;  // read by the next Start()
  return Status::Ok();
}

CaptureMode LibcameraStereoCamera::capture_mode() const { return impl_->mode; }

void LibcameraStereoCamera::SetColourWanted(bool colour) {
  impl_->colour_wanted = colour;  // read by the next Start()
}

Result<StereoSide> LibcameraStereoCamera::SilentSide() const { return impl_->pairer.SilentSide(); }

const LibcameraStreamInfo& LibcameraStereoCamera::stream_info() const { return impl_->info; }

int LibcameraStereoCamera::cameras_found() const { return impl_->cameras_found; }

}  // namespace sh::hal
