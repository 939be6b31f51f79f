#include "pdvo/infer/vanishing.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/common/geometry.h"
#include "pdvo/common/options.h"

namespace pdvo {
namespace {

constexpr double kDegree = M_PI / 180;
// Cauchy scale of m . up for the vertical edges, and the reweighting steps that find the vertical after a first
// plain least-squares fit.
constexpr double kVerticalResidualScale = 0.03;
constexpr int kVerticalIterations = 10;
// FuseNormal's search over phi: a coarse grid, then whole degrees around its best.
constexpr int kCoarseSteps = 36;

}  // namespace

bool VanishingOptions::Check() const {
  PDVO_CHECK_OPTION(field_of_view_deg > 1 && field_of_view_deg < 179);
  PDVO_CHECK_OPTION(tensor_sigma > 0);
  PDVO_CHECK_OPTION(min_strength >= 0);
  PDVO_CHECK_OPTION(min_coherence >= 0 && min_coherence <= 1);
  PDVO_CHECK_OPTION(vertical_band_deg > 0 && vertical_band_deg < 90);
  PDVO_CHECK_OPTION(max_tilt_deg > 0 && max_tilt_deg < 90);
  PDVO_CHECK_OPTION(min_edges >= 1);
  PDVO_CHECK_OPTION(max_edges >= min_edges);
  PDVO_CHECK_OPTION(residual_scale > 0);
  PDVO_CHECK_OPTION(prior_weight >= 0);
  PDVO_CHECK_OPTION(horizontal_cos > 0 && horizontal_cos <= 1);
  return true;
}

EdgePlanes FindEdgePlanes(const cv::Mat& image, const std::optional<Camera>& camera, const VanishingOptions& o) {
  PDVO_THROW_CHECK(!image.empty() && image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3),
                   InvalidArgument, "edge planes: expected an 8-bit grey or BGR image");
  const Camera k = camera.value_or(Camera::WithFieldOfView(image.cols, image.rows, o.field_of_view_deg));
  k.Check("edge planes");
  PDVO_THROW_CHECK(!k.HasDistortion() && k.width == image.cols && k.height == image.rows, InvalidArgument,
                   "edge planes: the camera (" << k.width << "x" << k.height << (k.HasDistortion() ? ", distorted" : "")
                                               << ") does not fit the " << image.cols << "x" << image.rows << " image");
  EdgePlanes e;
  e.camera = k;
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  // Scharr's derivatives (in grey levels per pixel): Sobel's pull the orientation of near-axis edges towards the
  // axis by about 10%, which tilts the vertical found by as much; Scharr's by 3-5%.
  cv::Mat gx, gy;
  cv::Scharr(grey, gx, CV_32F, 1, 0, 1.0 / 32);
  cv::Scharr(grey, gy, CV_32F, 0, 1, 1.0 / 32);
  cv::Mat xx = gx.mul(gx), xy = gx.mul(gy), yy = gy.mul(gy);
  for (cv::Mat* m : {&xx, &xy, &yy}) cv::GaussianBlur(*m, *m, cv::Size(), o.tensor_sigma);

  e.normals = cv::Mat::zeros(image.size(), CV_32FC3);
  e.strength = cv::Mat::zeros(image.size(), CV_32F);
  const double min_strength2 = o.min_strength * o.min_strength, vertical_sin = std::sin(o.vertical_band_deg * kDegree);
  std::vector<Eigen::Vector3d> vertical;
  std::vector<double> vertical_weight;
  for (int y = 0; y < image.rows; ++y) {
    const float *a = xx.ptr<float>(y), *b = xy.ptr<float>(y), *c = yy.ptr<float>(y);
    cv::Vec3f* normal = e.normals.ptr<cv::Vec3f>(y);
    float* strength = e.strength.ptr<float>(y);
    for (int x = 0; x < image.cols; ++x) {
      const double trace = a[x] + c[x];
      if (trace < min_strength2) continue;  // the larger eigenvalue is at most the trace
      const double gap = std::sqrt((a[x] - c[x]) * (a[x] - c[x]) + 4.0 * b[x] * b[x]);
      const double larger = 0.5 * (trace + gap);
      if (larger < min_strength2 || gap * gap < o.min_coherence * trace * trace || gap <= 0) continue;
      // The gradient's direction g is the larger eigenvector's: cos 2g = (a - c) / gap, sin 2g = 2 b / gap. The
      // edge runs across it: (ex, ey) = (-sin g, cos g).
      const double cos2 = (a[x] - c[x]) / gap;
      const double ey = std::sqrt(std::max(0.0, 0.5 * (1 + cos2)));
      const double ex = -std::copysign(std::sqrt(std::max(0.0, 0.5 * (1 - cos2))), b[x]);
      // The image line through (x, y) along (ex, ey), and the normal of its plane through the camera: K^T l.
      const double l0 = -ey, l1 = ex, l2 = x * ey - y * ex;
      const Eigen::Vector3d m = Eigen::Vector3d(k.fx * l0, k.fy * l1, k.cx * l0 + k.cy * l1 + l2).normalized();
      normal[x] = cv::Vec3f(m.x(), m.y(), m.z());
      strength[x] = static_cast<float>(std::sqrt(larger));
      if (std::abs(ex) < vertical_sin) {
        vertical.push_back(m);
        vertical_weight.push_back(strength[x]);
      }
    }
  }
  // The vertical: the direction all vertical lines' planes contain, by least squares, then reweighted.
  if (vertical.size() < static_cast<size_t>(2.5 * o.min_edges)) return e;
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  for (int it = 0; it <= kVerticalIterations; ++it) {
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < vertical.size(); ++i) {
      const double r = it == 0 ? 0 : vertical[i].dot(up) / kVerticalResidualScale;
      scatter += vertical_weight[i] / (1 + r * r) * vertical[i] * vertical[i].transpose();
    }
    up = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
    if (up.y() < 0) up = -up;
  }
  if (up.y() >= std::cos(o.max_tilt_deg * kDegree)) {
    e.up = up;
    e.up_found = true;
  }
  return e;
}

namespace {

// Calls visit(m, strength) for each edge pixel of the region.
template <class Visit>
void ForEachEdge(const EdgePlanes& edges, const Region& region, Visit visit) {
  const cv::Rect box = region.box & cv::Rect(0, 0, edges.normals.cols, edges.normals.rows);
  for (int y = box.y; y < box.y + box.height; ++y) {
    const cv::Vec3f* normal = edges.normals.ptr<cv::Vec3f>(y);
    const float* strength = edges.strength.ptr<float>(y);
    const uchar* mask_row = region.mask.empty() ? nullptr : region.mask.ptr<uchar>(y - region.box.y);
    for (int x = box.x; x < box.x + box.width; ++x) {
      if (strength[x] <= 0 || (mask_row && !mask_row[x - region.box.x])) continue;
      visit(Eigen::Vector3f(normal[x][0], normal[x][1], normal[x][2]), strength[x]);
    }
  }
}

}  // namespace

Eigen::Vector2d EdgeStructure(const EdgePlanes& edges, const Region& region, const VanishingOptions& o) {
  const double area = region.Area();
  if (edges.normals.empty() || area <= 0) return Eigen::Vector2d::Zero();
  const Eigen::Vector3f up = edges.up.cast<float>();
  const float vertical_sin = static_cast<float>(std::sin(o.vertical_band_deg * kDegree));
  double count = 0, strength = 0, vertical = 0;
  ForEachEdge(edges, region, [&](const Eigen::Vector3f& m, float s) {
    count += 1;
    strength += s;
    if (std::abs(m.dot(up)) < vertical_sin) vertical += s;
  });
  return {count / area, strength > 0 ? vertical / strength : 0.0};
}

Eigen::ArrayXXf AzimuthLikelihood::Losses(const std::vector<double>& phis) const {
  PDVO_THROW_CHECK(!empty(), InvalidArgument, "azimuth likelihood: no edges");
  // All the residuals in one matrix product and their logarithms several at a time (most of FuseNormal's time).
  const Eigen::Index n = static_cast<Eigen::Index>(constraints.size()), k = static_cast<Eigen::Index>(phis.size());
  const Eigen::Map<const Eigen::Matrix<float, 2, Eigen::Dynamic>> m(constraints.front().data(), 2, n);
  Eigen::Matrix<float, 2, Eigen::Dynamic> d(2, k);
  for (Eigen::Index j = 0; j < k; ++j) {
    d(0, j) = static_cast<float>(std::cos(phis[static_cast<size_t>(j)]) / residual_scale);
    d(1, j) = static_cast<float>(std::sin(phis[static_cast<size_t>(j)]) / residual_scale);
  }
  const Eigen::ArrayXXf r = (m.transpose() * d).array();  // n x k
  return (r * r).log1p();
}

std::vector<double> AzimuthLikelihood::MeanLogLikelihoods(const std::vector<double>& phis) const {
  const Eigen::ArrayXXf logs = Losses(phis);
  const Eigen::Index n = logs.rows(), k = logs.cols();
  const Eigen::Map<const Eigen::VectorXf> w(weights.data(), n);
  const Eigen::VectorXd sums = logs.matrix().cast<double>().transpose() * w.cast<double>();
  const double mass = w.cast<double>().sum();
  std::vector<double> out(static_cast<size_t>(k));
  for (Eigen::Index j = 0; j < k; ++j) out[static_cast<size_t>(j)] = -sums[j] / mass;
  return out;
}

Eigen::Vector3d AzimuthLikelihood::Normal(double phi, const Eigen::Vector3d& towards) const {
  const Eigen::Vector3d d = std::cos(phi) * e1 + std::sin(phi) * e2;
  const Eigen::Vector3d n = d.cross(up).normalized();
  return n.dot(towards) < 0 ? Eigen::Vector3d(-n) : n;
}

double AzimuthLikelihood::Phi(const Eigen::Vector3d& n) const {
  const Eigen::Vector3d d = up.cross(n);  // horizontal and in the plane
  double phi = std::atan2(d.dot(e2), d.dot(e1));
  if (phi < 0) phi += M_PI;
  return phi >= M_PI ? phi - M_PI : phi;
}

AzimuthLikelihood AzimuthBasis(const EdgePlanes& edges, const VanishingOptions& o) {
  AzimuthLikelihood l;
  l.up = edges.up;
  l.e1 = (Eigen::Vector3d::UnitX() - edges.up.x() * edges.up).normalized();
  l.e2 = l.e1.cross(edges.up);
  l.residual_scale = o.residual_scale;
  l.vertical_sin = std::sin(o.vertical_band_deg * kDegree);
  return l;
}

bool AzimuthLikelihood::Add(const Eigen::Vector3f& m, float strength) {
  if (std::abs(m.dot(up.cast<float>())) < static_cast<float>(vertical_sin)) return false;
  constraints.emplace_back(m.dot(e1.cast<float>()), m.dot(e2.cast<float>()));
  weights.push_back(strength);
  return true;
}

AzimuthLikelihood RegionAzimuthLikelihood(const EdgePlanes& edges, const Region& region, const VanishingOptions& o) {
  AzimuthLikelihood l = AzimuthBasis(edges, o);
  if (!edges.up_found) return l;
  ForEachEdge(edges, region, [&](const Eigen::Vector3f& m, float s) { l.Add(m, s); });
  const size_t n = l.constraints.size();
  if (n < static_cast<size_t>(o.min_edges)) {
    l.constraints.clear();
    l.weights.clear();
  } else if (n > static_cast<size_t>(o.max_edges)) {  // evenly spaced, in scan order
    const size_t keep = static_cast<size_t>(o.max_edges);
    for (size_t i = 0; i < keep; ++i) {
      l.constraints[i] = l.constraints[i * n / keep];
      l.weights[i] = l.weights[i * n / keep];
    }
    l.constraints.resize(keep);
    l.weights.resize(keep);
  }
  return l;
}

Eigen::Vector3d RegionRay(const Camera& camera, const Region& region) {
  return camera.Unproject({region.box.x + 0.5 * (region.box.width - 1), region.box.y + 0.5 * (region.box.height - 1)});
}

Eigen::Vector3d FuseNormal(const Eigen::Vector3d& model_normal, const EdgePlanes& edges, const Region& region,
                           const VanishingOptions& o) {
  const Eigen::Vector3d ray = RegionRay(edges.camera, region);
  if (!o.fuse_normals || !edges.up_found) return NearestFacingNormal(model_normal, ray);
  // The fused plane is seen, so it faces the camera at the region's centre: a horizontal plane below the
  // horizon from above, one above it from below; a vertical plane on the side of the ray.
  if (std::abs(model_normal.dot(edges.up)) > o.horizontal_cos) {
    return edges.up.dot(ray) < 0 ? edges.up : Eigen::Vector3d(-edges.up);
  }
  const AzimuthLikelihood l = RegionAzimuthLikelihood(edges, region, o);
  if (l.empty()) return NearestFacingNormal(model_normal, ray);
  const double prior_phi = l.Phi(model_normal);
  double best_phi = 0, best = -1e300;
  auto consider = [&](const std::vector<double>& phis) {  // the posterior's largest over phis, if larger
    const std::vector<double> likelihoods = l.MeanLogLikelihoods(phis);
    for (size_t i = 0; i < phis.size(); ++i) {
      const double p = o.prior_weight * std::cos(2 * (phis[i] - prior_phi)) + likelihoods[i];
      if (p > best) best = p, best_phi = phis[i];
    }
  };
  const double coarse = M_PI / kCoarseSteps;
  std::vector<double> phis;
  for (int i = 0; i < kCoarseSteps; ++i) phis.push_back((i + 0.5) * coarse);
  consider(phis);
  const double centre = best_phi;
  phis.clear();
  for (double step = -coarse / 2; step <= coarse / 2 + 1e-9; step += kDegree) phis.push_back(centre + step);
  consider(phis);
  return l.Normal(best_phi, -ray);
}

}  // namespace pdvo
