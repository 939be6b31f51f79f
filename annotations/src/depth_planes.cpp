#include "pdvo/annotations/depth_planes.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>

#include "pdvo/annotations/raster.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/options.h"

namespace pdvo {

bool DepthPlaneOptions::Check() const {
  PDVO_CHECK_OPTION(working_width >= 32);
  PDVO_CHECK_OPTION(min_depth >= 0 && max_depth > min_depth);
  PDVO_CHECK_OPTION(normal_radius >= 1 && normal_radius <= 20);
  PDVO_CHECK_OPTION(noise_a > 0 && noise_b >= 0);
  PDVO_CHECK_OPTION(inlier_sigmas > 0);
  PDVO_CHECK_OPTION(max_normal_angle_deg > 0 && max_normal_angle_deg < 90);
  PDVO_CHECK_OPTION(seed_max_residual > 0);
  PDVO_CHECK_OPTION(merge_angle_deg >= 0 && merge_angle_deg < 90);
  PDVO_CHECK_OPTION(min_plane_fraction > 0 && min_plane_fraction < 1);
  PDVO_CHECK_OPTION(nonplanar_residual > 0);
  PDVO_CHECK_OPTION(nonplanar_dispersion > 0 && nonplanar_dispersion <= 1);
  PDVO_CHECK_OPTION(min_nonplane_fraction > 0 && min_nonplane_fraction < 1);
  PDVO_CHECK_OPTION(min_hole_fraction >= 0 && min_hole_fraction < 1);
  PDVO_CHECK_OPTION(polygon_epsilon >= 0);
  return true;
}

namespace {

// Weighted sums of points and their outer products: least-squares plane fits, incrementally. Points are
// weighted by 1 / sigma(z)^2, so that far, noisy points do not bias the fit.
struct PlaneAccumulator {
  double n = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();

  void Add(const Eigen::Vector3d& p, double sigma) {
    const double w = 1.0 / (sigma * sigma);
    n += w;
    sum += w * p;
    outer += w * p * p.transpose();
  }
  // Normal (towards the camera at the origin) and distance of the best plane.
  void Fit(Eigen::Vector3d* normal, double* distance) const {
    const Eigen::Vector3d mean = sum / n;
    const Eigen::Matrix3d cov = outer / n - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(cov);
    Eigen::Vector3d nrm = eig.eigenvectors().col(0);
    if (nrm.dot(mean) > 0) nrm = -nrm;
    *normal = nrm;
    *distance = -nrm.dot(mean);
  }
};

double Sigma(const DepthPlaneOptions& o, double z) {
  const double dz = z - o.noise_z0;
  return o.noise_a + o.noise_b * dz * dz;
}

}  // namespace

DepthPlaneFinder::DepthPlaneFinder(const Camera& camera, const DepthPlaneOptions& options)
    : camera_(camera), options_(options) {
  camera.Check("annotate-depth camera");
  CheckOptionsOrThrow(options, "annotate-depth options");
  const int w = std::min(options.working_width, camera.width);
  const int h = static_cast<int>(std::lround(static_cast<double>(camera.height) * w / camera.width));
  source_x_.create(h, w, CV_32S);
  source_y_.create(h, w, CV_32S);
  ray_x_.create(h, w, CV_64F);
  ray_y_.create(h, w, CV_64F);
  std::vector<cv::Point2d> pixels;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int x = std::min(camera.width - 1, static_cast<int>((u + 0.5) * camera.width / w));
      const int y = std::min(camera.height - 1, static_cast<int>((v + 0.5) * camera.height / h));
      source_x_.at<int>(v, u) = x;
      source_y_.at<int>(v, u) = y;
      pixels.emplace_back(x, y);
    }
  }
  const std::vector<cv::Point2d> ideal = camera.UndistortPoints(pixels);
  for (int i = 0; i < w * h; ++i) {
    ray_x_.at<double>(i) = (ideal[i].x - camera.cx) / camera.fx;
    ray_y_.at<double>(i) = (ideal[i].y - camera.cy) / camera.fy;
  }
}

std::vector<DepthPlane> DepthPlaneFinder::FindPlanes(const cv::Mat& depth, cv::Mat* nonplanar_mask) const {
  PDVO_THROW_CHECK(depth.type() == CV_32F, InvalidArgument, "annotate-depth: depth must be CV_32F metres");
  PDVO_THROW_CHECK(depth.cols == camera_.width && depth.rows == camera_.height, InvalidArgument,
                   "annotate-depth: depth is " << depth.cols << "x" << depth.rows << " but the camera is "
                                               << camera_.width << "x" << camera_.height);
  const DepthPlaneOptions& o = options_;
  const int w = ray_x_.cols, h = ray_x_.rows, n_pixels = w * h;

  // 1. Points at working resolution, and their moments for local fits.
  std::vector<Eigen::Vector3d> points(n_pixels, Eigen::Vector3d::Zero());
  std::vector<double> sigma(n_pixels, 0);
  std::vector<uint8_t> valid(n_pixels, 0);
  cv::Mat moments(h, w, CV_64FC(10), cv::Scalar::all(0));
  for (int i = 0; i < n_pixels; ++i) {
    const float z = depth.at<float>(source_y_.at<int>(i), source_x_.at<int>(i));
    if (!(z > o.min_depth && z < o.max_depth)) continue;
    const Eigen::Vector3d p(z * ray_x_.at<double>(i), z * ray_y_.at<double>(i), z);
    points[i] = p;
    sigma[i] = Sigma(o, z);
    valid[i] = 1;
    double* m = moments.ptr<double>(0) + 10 * i;
    m[0] = 1;
    m[1] = p.x(), m[2] = p.y(), m[3] = p.z();
    m[4] = p.x() * p.x(), m[5] = p.x() * p.y(), m[6] = p.x() * p.z();
    m[7] = p.y() * p.y(), m[8] = p.y() * p.z(), m[9] = p.z() * p.z();
  }
  const int r = o.normal_radius, window = (2 * r + 1) * (2 * r + 1);
  cv::Mat sums;
  cv::boxFilter(moments, sums, CV_64F, cv::Size(2 * r + 1, 2 * r + 1), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);

  // 2. Local plane fits: normal and RMS residual (in sigma) per pixel with enough valid neighbours.
  std::vector<Eigen::Vector3d> local_normal(n_pixels, Eigen::Vector3d::Zero());
  std::vector<double> local_residual(n_pixels, -1);
  for (int i = 0; i < n_pixels; ++i) {
    if (!valid[i]) continue;
    const double* s = sums.ptr<double>(0) + 10 * i;
    if (s[0] < 0.6 * window) continue;
    const Eigen::Vector3d mean(s[1] / s[0], s[2] / s[0], s[3] / s[0]);
    Eigen::Matrix3d cov;
    cov << s[4], s[5], s[6], s[5], s[7], s[8], s[6], s[8], s[9];
    cov = cov / s[0] - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(cov);
    Eigen::Vector3d nrm = eig.eigenvectors().col(0);
    if (nrm.dot(mean) > 0) nrm = -nrm;
    local_normal[i] = nrm;
    local_residual[i] = std::sqrt(std::max(0.0, eig.eigenvalues()(0))) / sigma[i];
  }

  // 3. Region growing from the flattest seeds. Regions too small to keep give their pixels back.
  std::vector<int> order;
  for (int i = 0; i < n_pixels; ++i) {
    if (local_residual[i] >= 0 && local_residual[i] < o.seed_max_residual) order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return local_residual[a] < local_residual[b]; });
  const double cos_max = std::cos(o.max_normal_angle_deg * M_PI / 180.0);
  const int min_plane_pixels = static_cast<int>(o.min_plane_fraction * n_pixels);
  const int offsets[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  auto residual_of = [&](int q, const DepthPlane& plane) {
    return std::abs(plane.normal.dot(points[q]) + plane.distance) / sigma[q];
  };
  std::vector<int> label(n_pixels, -1);
  std::vector<uint8_t> seeded(n_pixels, 0);
  std::vector<DepthPlane> regions;  // the fit that grew each region
  std::vector<int> region;
  for (int seed : order) {
    if (label[seed] >= 0 || seeded[seed]) continue;
    const int id = static_cast<int>(regions.size());
    DepthPlane plane;
    plane.normal = local_normal[seed];
    plane.distance = -plane.normal.dot(points[seed]);
    PlaneAccumulator acc;
    region.assign(1, seed);
    label[seed] = id;
    acc.Add(points[seed], sigma[seed]);
    size_t next_refit = 32;
    for (size_t head = 0; head < region.size(); ++head) {
      const int p = region[head];
      const int px = p % w, py = p / w;
      for (const auto& d : offsets) {
        const int qx = px + d[0], qy = py + d[1];
        if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
        const int q = qy * w + qx;
        if (label[q] >= 0 || !valid[q]) continue;
        if (local_residual[q] < 0 || local_normal[q].dot(plane.normal) < cos_max) continue;
        if (residual_of(q, plane) >= o.inlier_sigmas) continue;
        label[q] = id;
        region.push_back(q);
        acc.Add(points[q], sigma[q]);
      }
      if (region.size() >= next_refit) {
        acc.Fit(&plane.normal, &plane.distance);
        next_refit *= 2;
      }
    }
    for (int q : region) seeded[q] = 1;
    if (static_cast<int>(region.size()) < min_plane_pixels) {
      for (int q : region) label[q] = -1;
      continue;
    }
    acc.Fit(&plane.normal, &plane.distance);
    regions.push_back(plane);
  }

  // 4. Pixels along the regions' edges, whose windows straddled an edge and so failed the normal test: ring by
  // ring out to the window radius, each goes to the neighbouring region it fits best, by distance alone.
  for (int ring = 0; ring <= r; ++ring) {
    std::vector<std::pair<int, int>> claims;
    for (int q = 0; q < n_pixels; ++q) {
      if (label[q] >= 0 || !valid[q]) continue;
      const int qx = q % w, qy = q / w;
      int best = -1;
      double best_residual = o.inlier_sigmas;
      for (const auto& d : offsets) {
        const int px = qx + d[0], py = qy + d[1];
        if (px < 0 || py < 0 || px >= w || py >= h) continue;
        const int id = label[py * w + px];
        if (id < 0 || id == best) continue;
        const double residual = residual_of(q, regions[id]);
        if (residual < best_residual) best = id, best_residual = residual;
      }
      if (best >= 0) claims.emplace_back(q, best);
    }
    if (claims.empty()) break;
    for (const auto& [q, id] : claims) label[q] = id;
  }

  // 5. Regions of one surface that growth split (depth sensors bend large planes a little) are merged: their
  // normals agree within `merge_angle_deg` and most pixels along their seam fit both planes (a step, such
  // as a keyboard on a desk, does not).
  const int n_regions = static_cast<int>(regions.size());
  std::vector<int> seam(n_regions * n_regions, 0), seam_fit(n_regions * n_regions, 0);
  for (int p = 0; p < n_pixels; ++p) {
    if (label[p] < 0) continue;
    const int px = p % w, py = p / w;
    for (const int q : {px + 1 < w ? p + 1 : -1, py + 1 < h ? p + w : -1}) {
      if (q < 0 || label[q] < 0 || label[q] == label[p]) continue;
      const int a = std::min(label[p], label[q]), b = std::max(label[p], label[q]);
      ++seam[a * n_regions + b];
      const bool fits =
          std::max({residual_of(p, regions[label[q]]), residual_of(q, regions[label[p]])}) < o.inlier_sigmas;
      seam_fit[a * n_regions + b] += fits;
    }
  }
  std::vector<int> parent(n_regions);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const double cos_merge = std::cos(o.merge_angle_deg * M_PI / 180.0);
  for (int a = 0; a < n_regions; ++a) {
    for (int b = a + 1; b < n_regions; ++b) {
      const int n = seam[a * n_regions + b];
      if (n < 2 * r || seam_fit[a * n_regions + b] < 0.5 * n) continue;
      if (regions[a].normal.dot(regions[b].normal) < cos_merge) continue;
      parent[root(b)] = root(a);
    }
  }

  // 6. The final fit of each merged region, from pixels whose own windows lie on it: flat, with a local normal
  // within `merge_angle_deg` of the region's (windows that straddle an edge are neither).
  std::vector<PlaneAccumulator> flat(n_regions), all(n_regions);
  for (int q = 0; q < n_pixels; ++q) {
    if (label[q] < 0) continue;
    const int grown = label[q];
    label[q] = root(grown);
    all[label[q]].Add(points[q], sigma[q]);
    if (local_residual[q] >= 0 && local_residual[q] < o.nonplanar_residual &&
        local_normal[q].dot(regions[grown].normal) > cos_merge) {
      flat[label[q]].Add(points[q], sigma[q]);
    }
  }
  std::vector<DepthPlane> planes;
  std::vector<int> plane_of(n_regions, -1);
  for (int id = 0; id < n_regions; ++id) {
    if (root(id) != id) continue;
    DepthPlane plane;
    (flat[id].n > 0 ? flat[id] : all[id]).Fit(&plane.normal, &plane.distance);
    plane.mask = cv::Mat(h, w, CV_8U, cv::Scalar(0));
    plane_of[id] = static_cast<int>(planes.size());
    planes.push_back(std::move(plane));
  }
  std::vector<double> squares(planes.size(), 0);
  for (int q = 0; q < n_pixels; ++q) {
    if (label[q] < 0) continue;
    DepthPlane& plane = planes[plane_of[label[q]]];
    plane.mask.at<uchar>(q) = 255;
    const double e = residual_of(q, plane);
    squares[plane_of[label[q]]] += e * e;
  }
  for (size_t i = 0; i < planes.size(); ++i) {
    planes[i].rms_sigmas = std::sqrt(squares[i] / std::max(1, cv::countNonZero(planes[i].mask)));
  }
  std::stable_sort(planes.begin(), planes.end(), [](const DepthPlane& a, const DepthPlane& b) {
    return cv::countNonZero(a.mask) > cv::countNonZero(b.mask);
  });

  // 7. Clearly non-planar pixels, away from every plane: rough at the window's scale, or with local normals
  // that disagree over a window twice as wide.
  if (nonplanar_mask) {
    cv::Mat normals(h, w, CV_64FC4, cv::Scalar::all(0));
    for (int i = 0; i < n_pixels; ++i) {
      if (local_residual[i] < 0) continue;
      normals.at<cv::Vec4d>(i) = cv::Vec4d(local_normal[i].x(), local_normal[i].y(), local_normal[i].z(), 1.0);
    }
    cv::Mat normal_sums;
    cv::boxFilter(normals, normal_sums, CV_64F, cv::Size(4 * r + 1, 4 * r + 1), cv::Point(-1, -1), false,
                  cv::BORDER_CONSTANT);
    cv::Mat rough(h, w, CV_8U, cv::Scalar(0));
    for (int i = 0; i < n_pixels; ++i) {
      if (local_residual[i] < 0 || label[i] >= 0) continue;
      const cv::Vec4d& s = normal_sums.at<cv::Vec4d>(i);
      const double dispersion = 1.0 - std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) / s[3];
      if (local_residual[i] > o.nonplanar_residual || dispersion > o.nonplanar_dispersion) rough.at<uchar>(i) = 255;
    }
    // Opening drops the thin lines along depth edges; closing joins what is left into blobs.
    cv::morphologyEx(rough, rough, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
    cv::morphologyEx(rough, rough, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(9, 9)));
    *nonplanar_mask = rough;
  }
  return planes;
}

Annotation DepthPlaneFinder::Annotate(const cv::Mat& depth, const std::string& image_path) const {
  cv::Mat nonplanar;
  const std::vector<DepthPlane> planes = FindPlanes(depth, &nonplanar);
  const int n_pixels = ray_x_.cols * ray_x_.rows;
  MaskPolygonOptions polygons;
  polygons.min_plane_pixels = static_cast<int>(options_.min_plane_fraction * n_pixels);
  polygons.min_nonplane_pixels = static_cast<int>(options_.min_nonplane_fraction * n_pixels);
  polygons.min_hole_pixels = std::max(4, static_cast<int>(options_.min_hole_fraction * n_pixels));
  polygons.epsilon_full_px = options_.polygon_epsilon;
  Annotation a;
  a.image_path = image_path;
  a.image_width = camera_.width;
  a.image_height = camera_.height;
  a.camera = camera_.Undistorted();  // the format holds pinhole intrinsics
  AddShapesFromMasks(std::vector<PlaneMask>(planes.begin(), planes.end()), nonplanar, polygons, &a);
  return a;
}

}  // namespace pdvo
