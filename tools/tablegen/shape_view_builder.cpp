#include "tools/tablegen/shape_view_builder.hpp"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <memory>

#include "recog/base/crc32.hpp"
#include "recog/shape/colour_classes.hpp"
#include "recog/shape/shape_window.hpp"
#include "recog/shape/silhouette.hpp"
#include "recog/shape/view_database.hpp"
#include "recog/verify/visible_edges.hpp"
#include "tools/tablegen/blob_writer.hpp"
#include "tools/tablegen/model_symmetry.hpp"

namespace sh {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Sample {
  uint16_t model;
  Eigen::Matrix3f R;  // ray_R_model
};

// Deterministic Gaussian numbers (SplitMix64 and Box-Muller), independent of the library.
class Gaussian {
 public:
  explicit Gaussian(uint64_t seed) : state_(seed) {}
  double Next() {
    const double u1 = (static_cast<double>(Bits() >> 11) + 0.5) * (1.0 / 9007199254740992.0);
    const double u2 = static_cast<double>(Bits() >> 11) * (1.0 / 9007199254740992.0);
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
  }

 private:
  uint64_t Bits() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  uint64_t state_;
};

// Orientations of one model: Fibonacci directions x in-plane angles, one per symmetry class.
std::vector<Eigen::Matrix3f> SampleOrientations(const Model& model, float spacing_deg) {
  const double step = spacing_deg * kPi / 180.0;
  const int n_dirs = std::max(2, static_cast<int>(std::lround(4.0 * kPi / (step * step))));
  const int n_psi = std::max(1, static_cast<int>(std::lround(360.0 / spacing_deg)));
  const Eigen::Matrix3f ref =
      Eigen::Quaternionf(0.8f, 0.3f, -0.4f, 0.25f).normalized().toRotationMatrix();
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Matrix3f> out;
  for (int i = 0; i < n_dirs; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n_dirs;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden * i;
    // Direction from the model origin to the camera, in the model frame; the camera looks along
    // +z of the ray frame, so that direction must become -z.
    const Eigen::Vector3f d(static_cast<float>(r * std::cos(phi)),
                            static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
    const Eigen::Matrix3f base =
        Eigen::Quaternionf::FromTwoVectors(d, -Eigen::Vector3f::UnitZ()).toRotationMatrix();
    for (int k = 0; k < n_psi; ++k) {
      const float psi = static_cast<float>(2.0 * kPi * k / n_psi);
      const Eigen::Matrix3f R =
          Eigen::AngleAxisf(psi, Eigen::Vector3f::UnitZ()).toRotationMatrix() * base;
      // Keep R when no symmetric equivalent R S lies nearer the reference (larger trace).
      const float own = (ref.transpose() * R).trace();
      bool keep = true;
      for (int s = 1; s < model.n_symmetries && keep; ++s) {
        keep = (ref.transpose() * R * model.symmetry(s)).trace() <= own + 1e-6f;
      }
      if (keep) out.push_back(R);
    }
  }
  return out;
}

struct RenderedView {
  ShapeWindow window;
  float extent_mm[2];
};

class ViewRenderer {
 public:
  explicit ViewRenderer(const ShapeViewBuildOptions& o)
      : options_(o),
        silhouette_(std::make_unique<SilhouetteScratch>()),
        window_(std::make_unique<ShapeWindowScratch>()) {}

  Status Render(const Model& model, float radius_mm, const Eigen::Matrix3f& R, RenderedView* out) {
    const float f = options_.render_focal_px, D = options_.render_distance_mm;
    const int half = static_cast<int>(std::ceil(f * radius_mm / (D - radius_mm))) + 2;
    ViewCamera camera;
    camera.intrinsics.width = camera.intrinsics.height = 2 * half + 1;
    camera.intrinsics.fx = camera.intrinsics.fy = f;
    camera.intrinsics.cx = camera.intrinsics.cy = half;
    PosedModel object{&model, {R, Eigen::Vector3f(0, 0, D)}};
    SilhouetteMask mask;
    SH_RETURN_IF_ERROR(RasterizeSilhouette(camera, object, *silhouette_, &mask));
    if (mask.empty() || mask.clipped) {
      return Status::Error(StatusCode::kInternal, "view of '%s' does not fit its camera",
                           model.name);
    }
    // Tight box of the set pixels: what a segmented region's box would be.
    int x0 = mask.width, x1 = -1, y0 = mask.height, y1 = -1;
    for (int y = 0; y < mask.height; ++y) {
      for (int x = 0; x < mask.width; ++x) {
        if (mask.mask[y * mask.width + x]) {
          x0 = std::min(x0, x);
          x1 = std::max(x1, x);
          y0 = std::min(y0, y);
          y1 = std::max(y1, y);
        }
      }
    }
    const ConstGrayView tight{mask.mask + ptrdiff_t{y0} * mask.width + x0, x1 - x0 + 1, y1 - y0 + 1,
                              mask.width};
    SH_RETURN_IF_ERROR(ComputeShapeWindow(tight, *window_, &out->window));
    // Box size in pixels -> millimetres at the origin's depth.
    out->extent_mm[0] = static_cast<float>(tight.width) * D / f;
    out->extent_mm[1] = static_cast<float>(tight.height) * D / f;
    return Status::Ok();
  }

 private:
  ShapeViewBuildOptions options_;
  std::unique_ptr<SilhouetteScratch> silhouette_;
  std::unique_ptr<ShapeWindowScratch> window_;
};

using RowMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

void Orthonormalise(Eigen::MatrixXf& m) {
  Eigen::HouseholderQR<Eigen::MatrixXf> qr(m);
  m = qr.householderQ() * Eigen::MatrixXf::Identity(m.rows(), m.cols());
}

// Randomised PCA (Halko, Martinsson & Tropp 2011, with power iterations): the top `k`
// principal directions of the rows of X (centred in place), as columns.
Eigen::MatrixXf PrincipalDirections(RowMatrix& X, int k, int power_iterations,
                                    Eigen::VectorXf* mean, float* explained) {
  *mean = X.colwise().mean().transpose();
  X.rowwise() -= mean->transpose();
  const int l = k + 10;
  Gaussian g(0x5eed5eedull);
  Eigen::MatrixXf omega(X.cols(), l);
  for (int j = 0; j < l; ++j) {
    for (int i = 0; i < X.cols(); ++i) omega(i, j) = static_cast<float>(g.Next());
  }
  Eigen::MatrixXf Q = X * omega;
  Orthonormalise(Q);
  for (int it = 0; it < power_iterations; ++it) {
    Eigen::MatrixXf Z = X.transpose() * Q;
    Orthonormalise(Z);
    Q = X * Z;
    Orthonormalise(Q);
  }
  const Eigen::MatrixXd B = (Q.transpose() * X).cast<double>();  // l x pixels
  // The right singular vectors of B from the eigenvectors of the small l x l matrix B B^T (in
  // double: the squared condition number costs nothing there): B^T u_i / s_i, s_i^2 the
  // eigenvalues. Directions without variance (s_i ~ 0, fewer views than components) stay zero.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(B * B.transpose());
  const Eigen::VectorXd& lambda = eigen.eigenvalues();  // ascending
  const double total = static_cast<double>(X.squaredNorm());
  const double largest = std::max(lambda(l - 1), 0.0);
  double kept = 0;
  Eigen::MatrixXf V = Eigen::MatrixXf::Zero(X.cols(), k);
  for (int i = 0; i < k; ++i) {
    const double s2 = lambda(l - 1 - i);
    if (!(s2 > largest * 1e-14)) continue;  // also s2 <= 0, as largest >= 0
    kept += s2;
    V.col(i) = (B.transpose() * eigen.eigenvectors().col(l - 1 - i) / std::sqrt(s2)).cast<float>();
  }
  *explained = total > 0 ? static_cast<float>(kept / total) : 0.0f;
  for (int i = 0; i < k; ++i) {  // sign: largest entry positive (deterministic output)
    Eigen::Index arg;
    V.col(i).cwiseAbs().maxCoeff(&arg);
    if (V(arg, i) < 0) V.col(i) = -V.col(i);
  }
  return V;
}

// The colours the recogniser's segmentation takes (DeriveColourClasses), checked when the set
// is built: a grey, white or missing Kd (an undefined material reads as white) is refused here,
// naming the part, instead of writing a set that recognize then refuses.
Status CheckColours(const std::vector<ShapeModelInput>& models) {
  std::vector<float> kd;
  for (const ShapeModelInput& in : models) {
    ColourClassSet one;
    uint8_t class_id = 0;
    const Status s = DeriveColourClasses(&in.kd, 1, &one, &class_id);
    if (!s.ok()) return Status::Error(s.code(), "colour part '%s': %s", in.model.name, s.message());
    kd.insert(kd.end(), in.kd, in.kd + 3);
  }
  ColourClassSet all;
  std::vector<uint8_t> class_of_model(models.size());
  return DeriveColourClasses(reinterpret_cast<const float(*)[3]>(kd.data()), int(models.size()),
                             &all, class_of_model.data());
}

// The model count and options BuildShapeViewBlob accepts.
Status CheckShapeViewOptions(size_t n_models, const ShapeViewBuildOptions& options) {
  if (n_models == 0 || n_models > kMaxShapeModels) {
    return Status::Error(StatusCode::kOutOfRange, "view database: %zu models (1..%u)", n_models,
                         kMaxShapeModels);
  }
  if (!(options.view_spacing_deg >= 2.0f && options.view_spacing_deg <= 45.0f)) {
    return Status::Error(StatusCode::kOutOfRange, "view database: spacing %.1f deg outside 2..45",
                         double(options.view_spacing_deg));
  }
  if (options.n_components < 1 || options.n_components > static_cast<int>(kMaxShapeComponents)) {
    return Status::Error(StatusCode::kOutOfRange, "view database: %d components (1..%u)",
                         options.n_components, kMaxShapeComponents);
  }
  if (!(options.render_focal_px > 0) || !(options.render_distance_mm > 0) ||
      options.pca_views < options.n_components || options.power_iterations < 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "view database: bad render camera or PCA settings");
  }
  return Status::Ok();
}

// The models with their symmetry groups (stored in them), records (colour, radius, views) and
// orientation samples; n_views counts the views of all.
struct SampledModels {
  std::vector<ShapeModelRecord> records;
  std::vector<std::vector<Eigen::Matrix3f>> orientations;
  size_t n_views = 0;
};

Status SampleModels(std::vector<ShapeModelInput>& models, const ShapeViewBuildOptions& options,
                    SampledModels* out) {
  std::vector<ShapeModelRecord>& records = out->records;
  std::vector<std::vector<Eigen::Matrix3f>>& orientations = out->orientations;
  size_t& n_views = out->n_views;
  records.resize(models.size());
  orientations.resize(models.size());
  n_views = 0;
  for (size_t m = 0; m < models.size(); ++m) {
    Model& model = models[m].model;
    SH_RETURN_IF_ERROR(CheckModel(model));
    StoreSymmetries(model, FindSymmetries(model));
    if (model.n_symmetries == 0) {
      return Status::Error(StatusCode::kInternal, "model '%s': no symmetry group", model.name);
    }
    float radius = 0;
    for (int i = 0; i < model.n_corners; ++i) radius = std::max(radius, model.corner(i).norm());
    if (!(radius > 0) || radius >= 0.5f * options.render_distance_mm) {
      return Status::Error(StatusCode::kOutOfRange,
                           "model '%s': radius %.1f mm does not fit the render distance %.0f mm",
                           model.name, double(radius), double(options.render_distance_mm));
    }
    ShapeModelRecord& r = records[m];
    for (int k = 0; k < 3; ++k) r.kd[k] = models[m].kd[k];
    r.radius_mm = radius;
    r.first_view = static_cast<uint32_t>(n_views);
    orientations[m] = SampleOrientations(model, options.view_spacing_deg);
    r.n_views = static_cast<uint32_t>(orientations[m].size());
    n_views += orientations[m].size();
  }
  if (n_views > kMaxShapeViews) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "view database: %zu views exceed %u; use a larger spacing", n_views,
                         kMaxShapeViews);
  }
  return Status::Ok();
}

// The PCA basis of the windows: k components (quantised, component-major), the mean window and
// the share of the fitted windows' energy the components explain.
struct WindowBasis {
  int k = 0;
  Eigen::VectorXf mean;
  float explained = 0;
  std::vector<QBasis::Raw> basis;
};

// PCA fitted to a per-model share of the views (every model is represented).
Status FitWindowBasis(const std::vector<ShapeModelInput>& models, const SampledModels& sampled,
                      const ShapeViewBuildOptions& options, ViewRenderer& renderer,
                      RenderedView* rendered_view, WindowBasis* out) {
  const std::vector<ShapeModelRecord>& records = sampled.records;
  const std::vector<std::vector<Eigen::Matrix3f>>& orientations = sampled.orientations;
  RenderedView& rendered = *rendered_view;
  const size_t quota = std::max<size_t>(1, options.pca_views / models.size());
  std::vector<std::pair<size_t, size_t>> fit;  // (model, orientation)
  for (size_t m = 0; m < models.size(); ++m) {
    const size_t n = orientations[m].size();
    const size_t take = std::min(n, quota);
    for (size_t i = 0; i < take; ++i) fit.push_back({m, i * n / take});
  }
  RowMatrix X(static_cast<Eigen::Index>(fit.size()), kWindowPixels);
  for (size_t i = 0; i < fit.size(); ++i) {
    const auto [m, o] = fit[i];
    SH_RETURN_IF_ERROR(
        renderer.Render(models[m].model, records[m].radius_mm, orientations[m][o], &rendered));
    X.row(static_cast<Eigen::Index>(i)) =
        Eigen::Map<const Eigen::RowVectorXf>(rendered.window.v, kWindowPixels);
  }
  const int k = std::min<int>(options.n_components, static_cast<int>(fit.size()) - 1);
  if (k < 1) return Status::Error(StatusCode::kInvalidArgument, "view database: too few views");
  out->k = k;
  const Eigen::MatrixXf V =
      PrincipalDirections(X, k, options.power_iterations, &out->mean, &out->explained);
  X.resize(0, 0);
  std::vector<QBasis::Raw>& basis = out->basis;
  basis.resize(static_cast<size_t>(k) * kWindowPixels);
  for (int c = 0; c < k; ++c) {
    for (int i = 0; i < kWindowPixels; ++i) {
      basis[static_cast<size_t>(c) * kWindowPixels + i] = QBasis::FromDouble(V(i, c)).raw();
    }
  }
  return Status::Ok();
}

// The header of n_models models and n_views views over `basis`, its sections placed.
ShapeViewsHeader LayOutShapeViews(size_t n_models, size_t n_views, const WindowBasis& basis,
                                  const ShapeViewBuildOptions& options) {
  const int k = basis.k;
  ShapeViewsHeader h{};
  std::memcpy(h.magic, kShapeViewsMagic, sizeof(h.magic));
  h.format_version = kShapeViewsVersion;
  h.window_side = kWindowSide;
  h.header_size = sizeof(ShapeViewsHeader);
  h.n_models = static_cast<uint32_t>(n_models);
  h.n_views = static_cast<uint32_t>(n_views);
  h.n_components = static_cast<uint16_t>(k);
  h.component_stride = static_cast<uint16_t>((k + 7) / 8 * 8);
  h.render_focal_px = options.render_focal_px;
  h.render_distance_mm = options.render_distance_mm;
  h.view_spacing_deg = options.view_spacing_deg;
  h.explained_energy = basis.explained;
  SectionLayout layout(sizeof(ShapeViewsHeader));
  layout.Place(&h.models, n_models * sizeof(Model));
  layout.Place(&h.shape_models, n_models * sizeof(ShapeModelRecord));
  layout.Place(&h.mean, kWindowPixels * sizeof(float));
  layout.Place(&h.basis, basis.basis.size() * sizeof(QBasis::Raw));
  layout.Place(&h.views, n_views * sizeof(ShapeViewRecord));
  layout.Place(&h.coefficients, n_views * h.component_stride * sizeof(QCoefficient::Raw));
  h.total_size = layout.total_size();
  return h;
}

// Every view into the blob laid out by h: render, window, project with the stored (quantised)
// basis.
Status WriteViews(const std::vector<ShapeModelInput>& models, const SampledModels& sampled,
                  const WindowBasis& pca, const ShapeViewsHeader& h, ViewRenderer& renderer,
                  RenderedView* rendered_view, std::vector<uint8_t>* blob) {
  const std::vector<ShapeModelRecord>& records = sampled.records;
  RenderedView& rendered = *rendered_view;
  auto* view_records = reinterpret_cast<ShapeViewRecord*>(blob->data() + h.views.offset);
  auto* coefficients = reinterpret_cast<QCoefficient::Raw*>(blob->data() + h.coefficients.offset);
  ShapeCoefficients c;
  size_t v = 0;
  for (size_t m = 0; m < models.size(); ++m) {
    for (const Eigen::Matrix3f& R : sampled.orientations[m]) {
      SH_RETURN_IF_ERROR(renderer.Render(models[m].model, records[m].radius_mm, R, &rendered));
      ProjectShapeWindow(pca.mean.data(), pca.basis.data(), pca.k, h.component_stride,
                         rendered.window, &c);
      std::memcpy(coefficients + v * h.component_stride, c.c,
                  h.component_stride * sizeof(QCoefficient::Raw));
      ShapeViewRecord& rec = view_records[v];
      Eigen::Quaternionf q(R);
      q.normalize();
      if (q.w() < 0) q.coeffs() = -q.coeffs();
      rec.q[0] = QQuaternion::FromDouble(q.w()).raw();
      rec.q[1] = QQuaternion::FromDouble(q.x()).raw();
      rec.q[2] = QQuaternion::FromDouble(q.y()).raw();
      rec.q[3] = QQuaternion::FromDouble(q.z()).raw();
      rec.model = static_cast<uint16_t>(m);
      rec.extent_mm[0] = UQExtentMm::FromDouble(rendered.extent_mm[0]).raw();
      rec.extent_mm[1] = UQExtentMm::FromDouble(rendered.extent_mm[1]).raw();
      ++v;
    }
  }
  return Status::Ok();
}

}  // namespace

Result<std::vector<uint8_t>> BuildShapeViewBlob(std::vector<ShapeModelInput> models,
                                                const ShapeViewBuildOptions& options,
                                                ShapeViewBuildReport* report) {
  SH_RETURN_IF_ERROR(CheckShapeViewOptions(models.size(), options));
  SH_RETURN_IF_ERROR(CheckColours(models));
  // Symmetry groups, radii and orientation samples.
  SampledModels sampled;
  SH_RETURN_IF_ERROR(SampleModels(models, options, &sampled));
  const std::vector<ShapeModelRecord>& records = sampled.records;
  const size_t n_views = sampled.n_views;
  ViewRenderer renderer(options);
  RenderedView rendered{};
  WindowBasis pca;
  SH_RETURN_IF_ERROR(FitWindowBasis(models, sampled, options, renderer, &rendered, &pca));

  ShapeViewsHeader h = LayOutShapeViews(models.size(), n_views, pca, options);
  std::vector<uint8_t> blob(h.total_size, 0);
  for (size_t m = 0; m < models.size(); ++m) {
    std::memcpy(blob.data() + h.models.offset + m * sizeof(Model), &models[m].model, sizeof(Model));
  }
  PutSection(blob, h.shape_models, records.data(), records.size());
  PutSection(blob, h.mean, pca.mean.data(), kWindowPixels);
  PutSection(blob, h.basis, pca.basis.data(), pca.basis.size());
  SH_RETURN_IF_ERROR(WriteViews(models, sampled, pca, h, renderer, &rendered, &blob));
  SealBlob(blob, h);

  if (report != nullptr) {
    report->per_model.clear();
    for (size_t m = 0; m < models.size(); ++m) {
      report->per_model.push_back(
          {models[m].model.name, records[m].n_views, models[m].model.n_symmetries});
    }
    report->views = static_cast<uint32_t>(n_views);
    report->explained_energy = pca.explained;
  }
  return blob;
}

}  // namespace sh
