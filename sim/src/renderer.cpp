#include "pdvo/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"

namespace pdvo::sim {

bool RenderOptions::Check() const {
  PDVO_CHECK_OPTION(noise_sigma >= 0 && noise_sigma < 50);
  PDVO_CHECK_OPTION(exposure_variation >= 0 && exposure_variation < 1);
  PDVO_CHECK_OPTION(motion_blur_samples >= 1 && motion_blur_samples <= 16);
  PDVO_CHECK_OPTION(exposure_fraction > 0 && exposure_fraction <= 1);
  PDVO_CHECK_OPTION(texels_per_metre >= 5 && texels_per_metre <= 200);
  PDVO_CHECK_OPTION(supersampling >= 1 && supersampling <= 4);
  return true;
}

namespace {

constexpr double kNear = 0.05;  // m
constexpr int kNoiseSize = 1024;

cv::Scalar Bgr(double b, double g, double r) { return cv::Scalar(255 * b, 255 * g, 255 * r); }

// Texture drawing, in metres on the plane: (u, v) with v up; the image has row 0 at the top.
class Painter {
 public:
  Painter(cv::Mat* image, double tpm, double height) : image_(image), tpm_(tpm), height_(height) {}
  cv::Rect Rect(double u0, double v0, double u1, double v1) const {
    const int x0 = static_cast<int>(std::floor(u0 * tpm_)), x1 = static_cast<int>(std::ceil(u1 * tpm_));
    const int y0 = static_cast<int>(std::floor((height_ - v1) * tpm_)),
              y1 = static_cast<int>(std::ceil((height_ - v0) * tpm_));
    return cv::Rect(x0, y0, std::max(1, x1 - x0), std::max(1, y1 - y0));
  }
  void Fill(double u0, double v0, double u1, double v1, const cv::Scalar& colour) {
    cv::rectangle(*image_, Rect(u0, v0, u1, v1), colour, cv::FILLED);
  }
  // Multiplies every channel by `factor` (CV_32F, the image's size).
  void Modulate(const cv::Mat& factor) {
    cv::Mat f;
    image_->convertTo(f, CV_32FC3);
    cv::Mat factor3;
    cv::merge(std::vector<cv::Mat>{factor, factor, factor}, factor3);
    f = f.mul(factor3);
    f.convertTo(*image_, CV_8UC3);
  }

 private:
  cv::Mat* image_;
  double tpm_, height_;
};

void AddGrain(cv::Mat& image, std::mt19937& rng, double amplitude) {
  cv::Mat noise(image.size(), CV_32F);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int i = 0; i < static_cast<int>(noise.total()); ++i) noise.at<float>(i) = u(rng);
  std::vector<cv::Mat> channels;
  cv::split(image, channels);
  for (cv::Mat& c : channels) {
    cv::Mat f;
    c.convertTo(f, CV_32F);
    f += noise * static_cast<float>(255 * amplitude);
    f.convertTo(c, CV_8U);
  }
  cv::merge(channels, image);
}

void PaintWall(Material material, Painter& p, const cv::Size& size, double width, double height, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  auto jitter = [&](double v, double amount) { return std::clamp(v * (1 + amount * (2 * u(rng) - 1)), 0.0, 1.0); };
  if (material == Material::kBrick) {
    const double b0 = 0.45 + 0.2 * u(rng), g0 = 0.3 + 0.15 * u(rng), r0 = 0.55 + 0.3 * u(rng);
    p.Fill(0, 0, width, height, Bgr(0.7, 0.72, 0.74));  // mortar
    int row = 0;
    for (double v = 0; v < height; v += 0.075, ++row) {
      for (double x = (row % 2) * -0.11; x < width; x += 0.23) {
        p.Fill(std::max(0.0, x), v + 0.01, x + 0.22, v + 0.075,
               Bgr(jitter(b0 * 0.5, 0.2), jitter(g0, 0.2), jitter(r0, 0.15)));
      }
    }
  } else if (material == Material::kStone) {
    const double base = 0.55 + 0.2 * u(rng);
    p.Fill(0, 0, width, height, Bgr(base * 0.7, base * 0.75, base * 0.8));
    int row = 0;
    for (double v = 0; v < height; v += 0.4, ++row) {
      for (double x = (row % 2) * -0.35; x < width; x += 0.7) {
        const double s = jitter(base, 0.12);
        p.Fill(std::max(0.0, x), v + 0.015, x + 0.685, v + 0.4, Bgr(s * 0.85, s * 0.92, s));
      }
    }
  } else {  // render: a pastel colour with soft blotches
    const cv::Scalar colour = Bgr(0.5 + 0.45 * u(rng), 0.5 + 0.45 * u(rng), 0.5 + 0.45 * u(rng));
    p.Fill(0, 0, width, height, colour);
    cv::Mat blotch(std::max(2, size.height / 40), std::max(2, size.width / 40), CV_32F);
    for (int i = 0; i < static_cast<int>(blotch.total()); ++i)
      blotch.at<float>(i) = static_cast<float>(0.9 + 0.2 * u(rng));
    cv::resize(blotch, blotch, size, 0, 0, cv::INTER_CUBIC);
    p.Modulate(blotch);
  }
}

void PaintWindow(Painter& p, double u0, double v0, double w, double h, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  const bool light_frame = u(rng) < 0.6;
  const cv::Scalar frame = light_frame ? Bgr(0.92, 0.93, 0.93) : Bgr(0.15, 0.15, 0.17);
  p.Fill(u0 - 0.07, v0 - 0.07, u0 + w + 0.07, v0 + h + 0.07, frame);
  // Glass reflects the sky: light at the top, darker below, with a diagonal highlight.
  const int bands = 8;
  const double tint = 0.3 + 0.3 * u(rng);
  for (int k = 0; k < bands; ++k) {
    const double f = static_cast<double>(k) / bands;
    p.Fill(u0, v0 + h * f, u0 + w, v0 + h * (f + 1.0 / bands),
           Bgr(0.35 + tint * f, 0.3 + 0.6 * tint * f, 0.25 + 0.4 * tint * f));
  }
  p.Fill(u0 + w * 0.15, v0 + h * 0.55, u0 + w * 0.3, v0 + h * 0.9, Bgr(0.85, 0.82, 0.8));
  p.Fill(u0 + w / 2 - 0.03, v0, u0 + w / 2 + 0.03, v0 + h, frame);  // mullion
}

void PaintFacade(Painter& p, double width, double height, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  // Ground floor: a door, maybe a shop window and a sign.
  const double door = 0.5 + u(rng) * std::max(0.0, width - 1.6);
  p.Fill(door, 0, door + 1.1, 2.3, Bgr(0.1 + 0.3 * u(rng), 0.15 + 0.2 * u(rng), 0.2 + 0.3 * u(rng)));
  p.Fill(door + 0.9, 1.0, door + 1.0, 1.1, Bgr(0.6, 0.7, 0.75));  // handle
  if (u(rng) < 0.6 && width > 5) {
    const double shop = door > width / 2 ? 0.6 : door + 1.6;
    const double shop_width = std::min(3.5, width - shop - 0.5);
    if (shop_width > 1.0) PaintWindow(p, shop, 0.5, shop_width, 1.9, rng);
    const cv::Scalar sign = Bgr(u(rng), u(rng), u(rng));
    p.Fill(0.3, 2.75, width - 0.3, 3.25, sign);
    for (double x = 0.6; x < width - 0.8; x += 0.35 + 0.2 * u(rng)) {  // letters
      p.Fill(x, 2.85, x + 0.2, 3.15, Bgr(1 - sign[0] / 255, 1 - sign[1] / 255, 1 - sign[2] / 255));
    }
  }
  // Upper floors: rows of windows.
  const double spacing = 2.2 + 0.8 * u(rng), w = 1.0 + 0.3 * u(rng), h = 1.3 + 0.3 * u(rng);
  const int columns = static_cast<int>((width - 0.6) / spacing);
  const double margin = (width - columns * spacing) / 2;
  for (double floor = 3.6; floor + h + 0.9 < height; floor += 3.1) {
    for (int c = 0; c < columns; ++c) PaintWindow(p, margin + c * spacing + (spacing - w) / 2, floor + 0.8, w, h, rng);
  }
}

cv::Mat MakeTexture(const WorldPlane& plane, double tpm) {
  const int cols = std::max(1, static_cast<int>(std::ceil(plane.width * tpm)));
  const int rows = std::max(1, static_cast<int>(std::ceil(plane.height * tpm)));
  cv::Mat t(rows, cols, CV_8UC3, cv::Scalar(128, 128, 128));
  std::mt19937 rng(plane.texture_seed);
  std::uniform_real_distribution<double> u(0, 1);
  Painter p(&t, tpm, plane.height);
  switch (plane.material) {
    case Material::kRoad: {  // across: u (0 .. road width); along: v
      t.setTo(Bgr(0.3, 0.3, 0.31));
      AddGrain(t, rng, 0.06);
      const double across = plane.width;
      p.Fill(0.25, 0, 0.37, plane.height, Bgr(0.85, 0.85, 0.85));
      p.Fill(across - 0.37, 0, across - 0.25, plane.height, Bgr(0.85, 0.85, 0.85));
      for (double v = 1.0; v < plane.height; v += 6.0)
        p.Fill(across / 2 - 0.06, v, across / 2 + 0.06, v + 3.0, Bgr(0.9, 0.9, 0.9));
      return t;
    }
    case Material::kPavement: {
      t.setTo(Bgr(0.45, 0.45, 0.47));
      const double tone = 0.62 + 0.1 * u(rng);
      for (double v = 0; v < plane.height; v += 0.5) {
        for (double x = 0; x < plane.width; x += 0.5) {
          const double s = tone * (0.93 + 0.14 * u(rng));
          p.Fill(x + 0.012, v + 0.012, x + 0.5, v + 0.5, Bgr(s, s, s * 1.02));
        }
      }
      AddGrain(t, rng, 0.03);
      return t;
    }
    default: {
      PaintWall(plane.material, p, t.size(), plane.width, plane.height, rng);
      AddGrain(t, rng, 0.025);
      if (plane.width > 3.0 && plane.height > 4.0) PaintFacade(p, plane.width, plane.height, rng);
      return t;
    }
  }
}

Eigen::Vector3d BlobNormal(const WorldBlob& b, const Eigen::Vector3d& x) {
  const Eigen::Vector3d v = x - b.centre;
  if (b.kind == WorldBlob::Kind::kCylinder) return Eigen::Vector3d(v.x(), 0, v.z()).normalized();
  const double c = std::cos(-b.yaw), s = std::sin(-b.yaw);
  const Eigen::Vector3d l(c * v.x() + s * v.z(), v.y(), -s * v.x() + c * v.z());
  const Eigen::Vector3d g(l.x() / (b.radii.x() * b.radii.x()), l.y() / (b.radii.y() * b.radii.y()),
                          l.z() / (b.radii.z() * b.radii.z()));
  // Back to the world: rotate by +yaw.
  return Eigen::Vector3d(c * g.x() - s * g.z(), g.y(), s * g.x() + c * g.z()).normalized();
}

uint32_t Hash(int x, int y, int z) {
  uint32_t h = static_cast<uint32_t>(x) * 73856093u ^ static_cast<uint32_t>(y) * 19349663u ^
               static_cast<uint32_t>(z) * 83492791u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  return h ^ (h >> 15);
}

}  // namespace

Renderer::Renderer(const Street& street, const Camera& camera, const RenderOptions& options, uint64_t seed)
    : street_(street), camera_(camera), options_(options) {
  camera.Check("synth camera");
  PDVO_THROW_CHECK(!camera.HasDistortion(), InvalidArgument, "synth: the camera must have no distortion");
  CheckOptionsOrThrow(options, "render options");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const double azimuth = 2 * M_PI * u(rng), elevation = (35 + 25 * u(rng)) * M_PI / 180;
  sun_ = Eigen::Vector3d(std::cos(elevation) * std::sin(azimuth), -std::sin(elevation),
                         std::cos(elevation) * std::cos(azimuth));
  exposure_phase_ = 2 * M_PI * u(rng);
  for (const WorldPlane& p : street.planes) {
    textures_.push_back(MakeTexture(p, options.texels_per_metre));
    plane_light_.push_back(0.55 + 0.5 * std::max(0.0, p.normal.dot(sun_)));
  }
  noise_.create(kNoiseSize, kNoiseSize, CV_32F);
  std::normal_distribution<float> gauss(0, 1);
  std::mt19937 noise_rng(static_cast<uint32_t>(seed));
  for (int i = 0; i < kNoiseSize * kNoiseSize; ++i) noise_.at<float>(i) = gauss(noise_rng);
  SetRays();
  if (options.supersampling > 1) {
    // Pixel u covers [u - 0.5, u + 0.5]; its k sub-pixels have centres u - 0.5 + (j + 0.5) / k. The fine
    // renderer shares the textures and the noise table (copies of a cv::Mat share its pixels).
    const int k = options.supersampling;
    auto fine = std::make_shared<Renderer>(*this);
    fine->camera_.width *= k;
    fine->camera_.height *= k;
    fine->camera_.fx *= k;
    fine->camera_.fy *= k;
    fine->camera_.cx = k * (camera.cx + 0.5) - 0.5;
    fine->camera_.cy = k * (camera.cy + 0.5) - 0.5;
    fine->options_.supersampling = 1;
    fine->SetRays();
    fine_ = std::move(fine);
  }
}

void Renderer::SetRays() {
  ray_x_.clear();
  ray_y_.clear();
  for (int x = 0; x < camera_.width; ++x) ray_x_.push_back((x - camera_.cx) / camera_.fx);
  for (int y = 0; y < camera_.height; ++y) ray_y_.push_back((y - camera_.cy) / camera_.fy);
}

void Renderer::RenderGeometry(const Rigid3d& world_from_cam, RenderedFrame* out) const {
  const int w = camera_.width, h = camera_.height;
  std::vector<double> inverse_depth(static_cast<size_t>(w) * h, 0.0);
  out->id.create(h, w, CV_32S);
  out->id.setTo(kSkyId);
  int* ids = out->id.ptr<int>();
  const Eigen::Matrix3d cam_from_world = world_from_cam.rotation.conjugate().toRotationMatrix();
  const Eigen::Vector3d& c = world_from_cam.translation;

  // Planes: clip each polygon at the near plane, project, and scan its rows; 1/z is linear in the pixel.
  std::vector<Eigen::Vector3d> clipped;
  std::vector<Eigen::Vector2d> projected;
  for (const WorldPlane& plane : street_.planes) {
    const double d_cam = plane.normal.dot(c) + plane.distance;
    if (d_cam <= 1e-9) continue;  // seen from behind
    const Eigen::Vector3d n = cam_from_world * plane.normal;
    clipped.clear();
    const size_t m = plane.polygon.size();
    for (size_t k = 0; k < m; ++k) {
      const Eigen::Vector3d a = cam_from_world * (plane.polygon[k] - c),
                            b = cam_from_world * (plane.polygon[(k + 1) % m] - c);
      if (a.z() >= kNear) clipped.push_back(a);
      if ((a.z() >= kNear) != (b.z() >= kNear)) clipped.push_back(a + (b - a) * ((kNear - a.z()) / (b.z() - a.z())));
    }
    if (clipped.size() < 3) continue;
    projected.clear();
    double y_min = 1e18, y_max = -1e18;
    for (const auto& x : clipped) {
      projected.emplace_back(camera_.fx * x.x() / x.z() + camera_.cx, camera_.fy * x.y() / x.z() + camera_.cy);
      y_min = std::min(y_min, projected.back().y());
      y_max = std::max(y_max, projected.back().y());
    }
    const int row0 = std::max(0, static_cast<int>(std::ceil(y_min))),
              row1 = std::min(h - 1, static_cast<int>(std::floor(y_max)));
    for (int v = row0; v <= row1; ++v) {
      double x_lo = 1e18, x_hi = -1e18;
      for (size_t k = 0; k < projected.size(); ++k) {
        const Eigen::Vector2d& a = projected[k];
        const Eigen::Vector2d& b = projected[(k + 1) % projected.size()];
        if ((a.y() - v) * (b.y() - v) > 0 || a.y() == b.y()) {
          if (a.y() == v) x_lo = std::min(x_lo, a.x()), x_hi = std::max(x_hi, a.x());
          continue;
        }
        const double x = a.x() + (v - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
        x_lo = std::min(x_lo, x);
        x_hi = std::max(x_hi, x);
      }
      const int col0 = std::max(0, static_cast<int>(std::ceil(x_lo))),
                col1 = std::min(w - 1, static_cast<int>(std::floor(x_hi)));
      const double row_term = n.y() * ray_y_[v] + n.z();
      for (int u = col0; u <= col1; ++u) {
        const double inv = -(n.x() * ray_x_[u] + row_term) / d_cam;
        const size_t i = static_cast<size_t>(v) * w + u;
        if (inv > inverse_depth[i]) {
          inverse_depth[i] = inv;
          ids[i] = plane.id;
        }
      }
    }
  }

  // Non-planar objects: ray cast inside each one's projected bounding box. In the object's own frame (the
  // unit sphere, or the cylinder's axis frame) the ray's direction is linear in the pixel's ray (x, y, 1), so
  // each pixel costs a few multiply-adds and one square root.
  const Eigen::Matrix3d world_from_cam_r = world_from_cam.rotation.toRotationMatrix();
  for (const WorldBlob& blob : street_.blobs) {
    const Eigen::Vector3d centre = cam_from_world * (blob.centre - c);
    const bool cylinder = blob.kind == WorldBlob::Kind::kCylinder;
    const double radius = cylinder ? std::hypot(blob.radii.x(), blob.radii.y()) : blob.radii.maxCoeff();
    if (centre.z() + radius < kNear || centre.z() - radius > 150) continue;
    int u0 = 0, u1 = w - 1, v0 = 0, v1 = h - 1;
    const double z_min = centre.z() - radius, z_max = centre.z() + radius;
    if (z_min > 2 * kNear) {
      auto bound = [&](double lo, double hi, double f, double cc, int size, int* a, int* b) {
        const double p = f * (lo < 0 ? lo / z_min : lo / z_max) + cc, q = f * (hi > 0 ? hi / z_min : hi / z_max) + cc;
        *a = std::max(0, static_cast<int>(std::floor(p)));
        *b = std::min(size - 1, static_cast<int>(std::ceil(q)));
      };
      bound(centre.x() - radius, centre.x() + radius, camera_.fx, camera_.cx, w, &u0, &u1);
      bound(centre.y() - radius, centre.y() + radius, camera_.fy, camera_.cy, h, &v0, &v1);
    }
    // local = M * world direction; origin o in the same frame.
    Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
    if (!cylinder) {
      const double cs = std::cos(-blob.yaw), sn = std::sin(-blob.yaw);
      m << cs / blob.radii.x(), 0, sn / blob.radii.x(), 0, 1 / blob.radii.y(), 0, -sn / blob.radii.z(), 0,
          cs / blob.radii.z();
    }
    const Eigen::Matrix3d l = m * world_from_cam_r;  // local direction = l * (x, y, 1)
    const Eigen::Vector3d o = m * (c - blob.centre);
    const double r2 = blob.radii.x() * blob.radii.x();
    // Cylinders use only x and z of the local direction; ellipsoids all three.
    const double qc = cylinder ? o.x() * o.x() + o.z() * o.z() - r2 : o.squaredNorm() - 1;
    const int label = BlobLabel(blob.id);
    for (int v = v0; v <= v1; ++v) {
      const Eigen::Vector3d row = l.col(1) * ray_y_[v] + l.col(2);
      for (int u = u0; u <= u1; ++u) {
        const Eigen::Vector3d d = row + l.col(0) * ray_x_[u];
        double qa, qb;
        if (cylinder) {
          qa = d.x() * d.x() + d.z() * d.z();
          qb = 2 * (o.x() * d.x() + o.z() * d.z());
        } else {
          qa = d.squaredNorm();
          qb = 2 * o.dot(d);
        }
        const double disc = qb * qb - 4 * qa * qc;
        if (disc < 0 || qa < 1e-12) continue;
        const double t = (-qb - std::sqrt(disc)) / (2 * qa);  // t is the depth z: the ray has z = 1
        if (t <= kNear || (cylinder && std::abs(o.y() + t * d.y()) > blob.radii.y())) continue;
        const size_t i = static_cast<size_t>(v) * w + u;
        if (1.0 / t > inverse_depth[i]) {
          inverse_depth[i] = 1.0 / t;
          ids[i] = label;
        }
      }
    }
  }
  out->depth.create(h, w, CV_32F);
  float* depth = out->depth.ptr<float>();
  for (size_t i = 0; i < inverse_depth.size(); ++i) {
    depth[i] = inverse_depth[i] > 0 ? static_cast<float>(1.0 / inverse_depth[i]) : 0.0f;
  }
}

void Renderer::Shade(const Rigid3d& world_from_cam, const RenderedFrame& g, cv::Mat* colour) const {
  const int w = camera_.width, h = camera_.height;
  const Eigen::Matrix3d r_wc = world_from_cam.rotation.toRotationMatrix();
  const Eigen::Matrix3d r_cw = r_wc.transpose();
  const Eigen::Vector3d& c = world_from_cam.translation;
  // Per plane: texture coordinates u = z * (a . ray) + b, and likewise v.
  struct Frame {
    Eigen::Vector3d au, av;
    double bu, bv;
  };
  std::vector<Frame> frames(street_.planes.size());
  for (size_t k = 0; k < street_.planes.size(); ++k) {
    const WorldPlane& p = street_.planes[k];
    frames[k] = {r_cw * p.axis_u, r_cw * p.axis_v, (c - p.origin).dot(p.axis_u), (c - p.origin).dot(p.axis_v)};
  }
  const double tpm = options_.texels_per_metre;
  for (int v = 0; v < h; ++v) {
    const int* ids = g.id.ptr<int>(v);
    const float* depth = g.depth.ptr<float>(v);
    cv::Vec3f* out = colour->ptr<cv::Vec3f>(v);
    for (int u = 0; u < w; ++u) {
      const int id = ids[u];
      const Eigen::Vector3d ray(ray_x_[u], ray_y_[v], 1.0);
      if (id >= 0) {
        const Frame& f = frames[id];
        const double z = depth[u];
        const double tu = z * f.au.dot(ray) + f.bu, tv = z * f.av.dot(ray) + f.bv;
        const cv::Mat& t = textures_[id];
        const int col = std::clamp(static_cast<int>(tu * tpm), 0, t.cols - 1);
        const int row = std::clamp(static_cast<int>((street_.planes[id].height - tv) * tpm), 0, t.rows - 1);
        const cv::Vec3b& texel = t.at<cv::Vec3b>(row, col);
        const float light = static_cast<float>(plane_light_[id]);
        out[u] += cv::Vec3f(texel[0], texel[1], texel[2]) * light;
      } else if (id == kSkyId) {
        const Eigen::Vector3d dir = (r_wc * ray).normalized();
        const double up = std::sqrt(std::max(0.0, -dir.y()));
        out[u] += cv::Vec3f(static_cast<float>(235 - 30 * up), static_cast<float>(215 - 70 * up),
                            static_cast<float>(195 - 110 * up));
      } else {
        const WorldBlob& b = street_.blobs[-2 - id];
        const Eigen::Vector3d x = c + r_wc * (depth[u] * ray);
        const double light = 0.5 + 0.55 * std::max(0.0, BlobNormal(b, x).dot(sun_));
        double texture = 1.0;
        if (b.material == Material::kLeaves) {
          const uint32_t hsh = Hash(static_cast<int>(std::floor(x.x() * 14)), static_cast<int>(std::floor(x.y() * 14)),
                                    static_cast<int>(std::floor(x.z() * 14)));
          texture = 0.55 + 0.8 * (hsh & 1023) / 1023.0;
        } else if (b.material == Material::kBark) {
          texture = 0.8 + 0.4 *
                              (Hash(0, static_cast<int>(std::floor(x.y() * 20)),
                                    static_cast<int>(std::atan2(x.z() - b.centre.z(), x.x() - b.centre.x()) * 8)) &
                               255) /
                              255.0;
        }
        const double k = 255 * light * texture;
        out[u] += cv::Vec3f(static_cast<float>(b.colour.x() * k), static_cast<float>(b.colour.y() * k),
                            static_cast<float>(b.colour.z() * k));
      }
    }
  }
}

void Renderer::Render(const std::vector<Rigid3d>& exposure_poses, double time, uint64_t frame_index,
                      RenderedFrame* out) const {
  PDVO_THROW_CHECK(!exposure_poses.empty(), InvalidArgument, "render: no pose");
  const int w = camera_.width, h = camera_.height;
  cv::Mat colour(h, w, CV_32FC3, cv::Scalar::all(0));
  if (fine_) {
    const Camera& f = fine_->camera_;
    cv::Mat fine_colour(f.height, f.width, CV_32FC3, cv::Scalar::all(0));
    RenderedFrame fine_geometry;
    for (const Rigid3d& pose : exposure_poses) {
      fine_->RenderGeometry(pose, &fine_geometry);
      fine_->Shade(pose, fine_geometry, &fine_colour);
    }
    cv::resize(fine_colour, colour, colour.size(), 0, 0, cv::INTER_AREA);
    RenderGeometry(exposure_poses.back(), out);
  } else {
    RenderedFrame blur;
    for (size_t k = 0; k + 1 < exposure_poses.size(); ++k) {
      RenderGeometry(exposure_poses[k], &blur);
      Shade(exposure_poses[k], blur, &colour);
    }
    RenderGeometry(exposure_poses.back(), out);
    Shade(exposure_poses.back(), *out, &colour);
  }
  const double gain = (1.0 + options_.exposure_variation * std::sin(2 * M_PI * 0.15 * time + exposure_phase_)) /
                      static_cast<double>(exposure_poses.size());
  // Sensor noise from the table, at an offset that changes every frame.
  const uint64_t hsh = frame_index * 0x9e3779b97f4a7c15ULL;
  const int ox = static_cast<int>(hsh % kNoiseSize), oy = static_cast<int>((hsh >> 20) % kNoiseSize);
  const float sigma = static_cast<float>(options_.noise_sigma);
  out->image.create(h, w, CV_8UC3);
  for (int v = 0; v < h; ++v) {
    const float* in = colour.ptr<float>(v);
    uchar* px = out->image.ptr<uchar>(v);
    const float* noise = noise_.ptr<float>((v + oy) % kNoiseSize);
    for (int k = 0, n = (ox % kNoiseSize); k < 3 * w; ++k, n = n + 1 == kNoiseSize ? 0 : n + 1) {
      px[k] = cv::saturate_cast<uchar>(in[k] * static_cast<float>(gain) + sigma * noise[n]);
    }
  }
}

}  // namespace pdvo::sim
