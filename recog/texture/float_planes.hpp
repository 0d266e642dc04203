// Float image planes of the texture path: conversion from 8-bit grey, separable Gaussian
// blurring and bilinear resampling, the building blocks of its scale pyramid.
//
// Pixel convention (as in recog/image): pixel (x, y) has its centre at (x, y). Intensities are
// on [0, 1] (8-bit value / 255), so responses and thresholds do not depend on the bit depth.
#pragma once

#include "recog/image/gaussian.hpp"
#include "recog/image/image.hpp"
#include "recog/texture/parallel.hpp"

namespace sh::texture {

using FloatView = ImageView<float>;
using ConstFloatView = ImageView<const float>;

// Packed float plane (stride == width) over caller storage of at least width * height floats.
inline FloatView PackedPlane(float* storage, int width, int height) {
  return {storage, width, height, width};
}

// out = image / 255. `out` must have the image's size.
void ToUnitFloat(const ConstGrayView& image, FloatView out);

// Separable Gaussian blur with a symmetric (order 0) kernel and replicated borders. `tmp` holds
// the row pass; in, tmp and out must have the same size and tmp must differ from both (in may be
// out). Values are the same as FilterRows / FilterColumns of recog/image on a float input.
// Rows are spread over `parallel` (the result does not depend on it).
void BlurPlane(const ConstFloatView& in, const GaussianKernel& kernel, FloatView tmp, FloatView out,
               const ParallelFor& parallel = {});

// Resamples `in` by `scale` (< 1 shrinks) with bilinear interpolation: out(x, y) = in(x / scale,
// y / scale), coordinates outside clamped to the border. Blur `in` first so that the result is
// not aliased. `out` must not overlap `in`.
void ResampleBilinear(const ConstFloatView& in, float scale, FloatView out,
                      const ParallelFor& parallel = {});

// Size of an image of width w resampled by scale: the pixels whose centre x / scale stays
// within [0, w - 1].
int ResampledSize(int size, float scale);

// Central-difference gradients (in(x + 1) - in(x - 1)) / 2, one-sided at the borders.
void CentralGradients(const ConstFloatView& in, FloatView gx, FloatView gy,
                      const ParallelFor& parallel = {});

// Bilinear sample at a real position; positions outside are clamped to the border pixels.
float SampleBilinear(const ConstFloatView& in, float x, float y);

}  // namespace sh::texture
