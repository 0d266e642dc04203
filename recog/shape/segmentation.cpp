#include "recog/shape/segmentation.hpp"

#include <algorithm>
#include <cstring>

namespace sh {

Status CheckSegmentConfig(const SegmentConfig& config) {
  if (config.min_area_px < 1 || config.min_area_px > 1000000) {
    return Status::Error(StatusCode::kOutOfRange, "segmentation: min_area_px %d outside 1..1e6",
                         config.min_area_px);
  }
  return Status::Ok();
}

uint32_t ColourSegmentation::Find(uint32_t i) {
  uint32_t root = i;
  while (runs_[root].parent != root) root = runs_[root].parent;
  while (runs_[i].parent != root) {  // path compression
    const uint32_t next = runs_[i].parent;
    runs_[i].parent = root;
    i = next;
  }
  return root;
}

void ColourSegmentation::Label(const ColourClassifier& classifier, const FrameView& frame) {
  size_t prev_begin = 0, prev_end = 0;
  const bool convert = frame.format != FrameFormat::kRgb888;
  rgb_view_ = convert ? ImageView<const Rgb8>{rgb_, width_, height_, width_} : frame.rgb;
  for (int y = 0; y < height_; ++y) {
    if (convert) FrameRowToRgb(frame, y, rgb_ + static_cast<size_t>(y) * width_);
    const Rgb8* row = rgb_view_.row(y);
    uint8_t* cls = classes_ + static_cast<size_t>(y) * width_;
    for (int x = 0; x < width_; ++x) cls[x] = classifier.Classify(row[x]);
    if (runs_truncated_) continue;  // keep classifying: the class image stays whole

    const size_t row_begin = runs_.size();
    size_t p = prev_begin;
    for (int x = 0; x < width_;) {
      const uint8_t c = cls[x];
      if (c == kNoColourClass) {
        ++x;
        continue;
      }
      int end = x + 1;
      while (end < width_ && cls[end] == c) ++end;
      ColourRun run;
      run.y = static_cast<uint16_t>(y);
      run.x0 = static_cast<uint16_t>(x);
      run.x1 = static_cast<uint16_t>(end);
      run.colour = c;
      run.parent = static_cast<uint32_t>(runs_.size());
      if (!runs_.push_back(run)) {
        // Full: this row and the rest stay unlabelled (a defined truncation, reported).
        runs_truncated_ = true;
        runs_.resize(row_begin);
        break;
      }
      const uint32_t self = run.parent;
      // Previous-row runs touching [x, end) with 8-connectivity: prev.x0 <= end and
      // prev.x1 >= x. Runs of a row are sorted and disjoint, so one pointer sweeps them.
      while (p < prev_end && runs_[p].x1 < x) ++p;
      for (size_t q = p; q < prev_end && runs_[q].x0 <= end; ++q) {
        if (runs_[q].colour != c) continue;
        const uint32_t a = Find(static_cast<uint32_t>(q)), b = Find(self);
        if (a != b) runs_[std::max(a, b)].parent = std::min(a, b);
      }
      x = end;
    }
    if (runs_truncated_) continue;
    prev_begin = row_begin;
    prev_end = runs_.size();
  }
}

void ColourSegmentation::CollectRegions(const SegmentConfig& config) {
  const size_t n = runs_.size();
  for (size_t i = 0; i < n; ++i) {
    const uint32_t root = Find(static_cast<uint32_t>(i));
    ColourRun& r = runs_[i];
    RootStats& s = root_stats_[root];
    if (root == i) s = {0, r.x0, r.y, r.x1 - 1, r.y, 0.0, 0.0, kNoRun, -1};
    const uint32_t len = uint32_t{r.x1} - r.x0;
    s.area += len;
    s.x0 = std::min<int>(s.x0, r.x0);
    s.x1 = std::max<int>(s.x1, r.x1 - 1);
    s.y1 = std::max<int>(s.y1, r.y);
    // Sum of x over x0 .. x1 - 1.
    s.sum_x += 0.5 * (double(r.x0) + double(r.x1) - 1.0) * len;
    s.sum_y += double(r.y) * len;
  }
  // Keep roots of at least min_area_px; when more than fit, the largest.
  for (size_t i = 0; i < n; ++i) root_stats_[i].region = -1;
  uint32_t region_root[kMaxColourRegions];
  for (size_t i = 0; i < n; ++i) {
    if (runs_[i].parent != i) continue;
    const RootStats& s = root_stats_[i];
    if (s.area < static_cast<uint32_t>(config.min_area_px)) continue;
    ColourRegion region;
    region.colour = runs_[i].colour;
    region.area_px = s.area;
    region.x0 = s.x0;
    region.y0 = s.y0;
    region.x1 = s.x1;
    region.y1 = s.y1;
    region.cx = static_cast<float>(s.sum_x / s.area);
    region.cy = static_cast<float>(s.sum_y / s.area);
    size_t slot = regions_.size();
    if (!regions_.push_back(region)) {
      regions_truncated_ = true;
      slot = 0;
      for (size_t k = 1; k < regions_.size(); ++k) {
        if (regions_[k].area_px < regions_[slot].area_px) slot = k;
      }
      if (regions_[slot].area_px >= region.area_px) continue;
      root_stats_[region_root[slot]].region = -1;
      regions_[slot] = region;
    }
    region_root[slot] = static_cast<uint32_t>(i);
    root_stats_[i].region = static_cast<int32_t>(slot);
  }
  // Chain the runs of each region in scan order.
  for (size_t i = 0; i < n; ++i) {
    const uint32_t root = runs_[i].parent;  // compressed to the root above
    const int32_t k = root_stats_[root].region;
    if (k < 0) continue;
    ColourRegion& region = regions_[k];
    if (region.first_run == kNoRun) {
      region.first_run = static_cast<uint32_t>(i);
    } else {
      runs_[root_stats_[root].last_run].next = static_cast<uint32_t>(i);
    }
    root_stats_[root].last_run = static_cast<uint32_t>(i);
    ++region.n_runs;
  }
}

Status ColourSegmentation::Segment(const FrameView& frame, const ColourClassifier& classifier,
                                   const SegmentConfig& config) {
  width_ = height_ = 0;
  runs_.clear();
  regions_.clear();
  runs_truncated_ = regions_truncated_ = false;
  SH_RETURN_IF_ERROR(CheckSegmentConfig(config));
  SH_RETURN_IF_ERROR(CheckFrame(frame));
  if (frame.width() > kMaxImageWidth || frame.height() > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "segmentation: frame %dx%d exceeds %dx%d",
                         frame.width(), frame.height(), kMaxImageWidth, kMaxImageHeight);
  }
  width_ = frame.width();
  height_ = frame.height();
  Label(classifier, frame);
  CollectRegions(config);
  return Status::Ok();
}

void RegionMask(const ColourRegion& region, const Vector<ColourRun>& runs, GrayView mask) {
  for (int y = 0; y < region.height(); ++y) std::memset(mask.row(y), 0, region.width());
  for (uint32_t i = region.first_run; i != kNoRun; i = runs[i].next) {
    const ColourRun& r = runs[i];
    std::memset(mask.row(r.y - region.y0) + (r.x0 - region.x0), 255, r.x1 - r.x0);
  }
}

}  // namespace sh
