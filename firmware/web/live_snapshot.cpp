#include "firmware/web/live_snapshot.hpp"

#include <cstring>

#include "firmware/canopen/od_table.hpp"
#include "firmware/web/web_limits.hpp"
#include "recog/pipeline/model_set.hpp"

namespace sh::fw::web {

int LiveScale(int width, int height) {
  int scale = 1;
  while ((width + scale - 1) / scale > kLiveMaxWidth ||
         (height + scale - 1) / scale > kLiveMaxHeight)
    scale *= 2;
  return scale;
}

Status LiveSnapshot::Init(const RigidTransform& camera_T_out) {
  camera_T_out_ = camera_T_out;
  for (auto& p : pixels_) p = std::make_unique<uint8_t[]>(size_t{kLiveMaxWidth} * kLiveMaxHeight);
  models_ = std::make_unique<Model[]>(canopen::kMaxModelNames);
  return Status::Ok();
}

void LiveSnapshot::Reduce(ConstGrayView image, int side) {
  if (image.empty()) {
    width_[side] = height_[side] = 0;
    return;
  }
  const int scale = LiveScale(image.width, image.height);
  const int w = (image.width + scale - 1) / scale, h = (image.height + scale - 1) / scale;
  for (int y = 0; y < h; ++y) {
    const uint8_t* row = image.row(y * scale);
    uint8_t* out = pixels_[side].get() + static_cast<ptrdiff_t>(y) * w;
    for (int x = 0; x < w; ++x) out[x] = row[static_cast<ptrdiff_t>(x) * scale];
  }
  width_[side] = w;
  height_[side] = h;
  scale_[side] = scale;
}

void LiveSnapshot::OnResult(const protocol::ResultSet& set, const hal::StereoFrame* frame) {
  if (capture_ != nullptr && frame != nullptr) capture_->OnFrame(*frame);
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || pixels_[0] == nullptr) {
    ++skipped_;  // the page is reading: this result is not shown, the next one is
    return;
  }
  result_.set = set;
  ++result_.results;
  result_.published_ns = MonotonicNs();
  result_.has_frame = frame != nullptr;
  if (frame == nullptr) return;  // the last images stay, the page says they are older
  const ConstGrayView sides[2] = {frame->left, frame->right};
  for (int side = 0; side < 2; ++side) {
    Reduce(sides[side], side);
    result_.full_width[side] = sides[side].empty() ? 0 : sides[side].width;
    result_.full_height[side] = sides[side].empty() ? 0 : sides[side].height;
  }
}

void LiveSnapshot::OnDataLoaded(const ModelSet& models) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (models_ == nullptr) return;
  model_count_ =
      models.count() < canopen::kMaxModelNames ? models.count() : canopen::kMaxModelNames;
  for (size_t m = 0; m < model_count_; ++m) models_[m] = models.model(static_cast<uint32_t>(m));
}

LiveResult LiveSnapshot::Result() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return result_;
}

bool LiveSnapshot::Image(int side, LiveImage* out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (side < 0 || side > 1 || width_[side] == 0) return false;
  out->width = width_[side];
  out->height = height_[side];
  out->scale = scale_[side];
  const uint8_t* p = pixels_[side].get();
  out->pixels.assign(p, p + size_t(out->width) * out->height);
  return true;
}

size_t LiveSnapshot::model_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return model_count_;
}

bool LiveSnapshot::CopyModel(size_t id, Model* out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (id >= model_count_) return false;
  *out = models_[id];
  return true;
}

}  // namespace sh::fw::web
