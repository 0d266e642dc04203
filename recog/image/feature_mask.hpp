// Image regions hidden from the feature detectors: objects another recogniser has already found
// in the frame (printed cartons found by their print). Their corners are dropped, and their edge
// pixels are cleared before line detection, so that neither the lines, the stereo scene built
// from them, nor the verifier (which reads the same edge map) sees them.
#pragma once

#include "recog/image/edge_map.hpp"

namespace sh {

class FeatureMask {
 public:
  virtual ~FeatureMask() = default;
  // Whether pixel position (x, y) (pixel centres at integers) is hidden.
  virtual bool Hides(float x_px, float y_px) const = 0;
  // Clears the edge pixels (edge = 0) of the hidden region; returns how many were set.
  virtual uint32_t ClearEdges(EdgeMapView edges) const = 0;
};

}  // namespace sh
