// Small scenes ray-cast into depth maps with exact labels: planes and spheres seen by a pinhole camera.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "pdvo/common/camera.h"

namespace pdvo::test {

struct ScenePlane {
  Eigen::Vector3d normal;  // unit, camera frame, towards the camera
  double distance;         // normal . x + distance = 0
};
struct SceneSphere {
  Eigen::Vector3d centre;
  double radius;
};

struct RenderedDepth {
  cv::Mat depth;  // CV_32F metres (z), 0 where nothing is hit
  cv::Mat label;  // CV_32S: plane index, or 1000 + sphere index, or -1
};

// Ray-casts through each pixel centre of an undistorted camera. Depth noise is Gaussian with
// sigma(z) = noise_a + noise_b (z - 0.4)^2 (0 to turn off).
inline RenderedDepth RenderDepth(const Camera& camera, const std::vector<ScenePlane>& planes,
                                 const std::vector<SceneSphere>& spheres, double noise_a, double noise_b,
                                 unsigned seed) {
  RenderedDepth out{cv::Mat(camera.height, camera.width, CV_32F, cv::Scalar(0)),
                    cv::Mat(camera.height, camera.width, CV_32S, cv::Scalar(-1))};
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0, 1);
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      double best = std::numeric_limits<double>::infinity();
      int id = -1;
      for (size_t i = 0; i < planes.size(); ++i) {
        const double denom = planes[i].normal.dot(ray);
        if (denom >= 0) continue;  // seen from behind or edge-on
        const double t = -planes[i].distance / denom;
        if (t > 0 && t < best) best = t, id = static_cast<int>(i);
      }
      for (size_t i = 0; i < spheres.size(); ++i) {
        const Eigen::Vector3d& c = spheres[i].centre;
        const double a = ray.squaredNorm(), b = -2 * ray.dot(c),
                     cc = c.squaredNorm() - spheres[i].radius * spheres[i].radius;
        const double disc = b * b - 4 * a * cc;
        if (disc < 0) continue;
        const double t = (-b - std::sqrt(disc)) / (2 * a);
        if (t > 0 && t < best) best = t, id = 1000 + static_cast<int>(i);
      }
      if (id < 0) continue;
      const double z = best;  // ray has z = 1, so t is the depth
      const double dz = z - 0.4;
      out.depth.at<float>(v, u) = static_cast<float>(z + (noise_a + noise_b * dz * dz) * gauss(rng));
      out.label.at<int>(v, u) = id;
    }
  }
  return out;
}

// The camera of these scenes: 320x240, 60 degrees wide.
inline Camera SceneCamera() {
  Camera c;
  c.width = 320;
  c.height = 240;
  c.fx = c.fy = 277.0;
  c.cx = 159.5;
  c.cy = 119.5;
  return c;
}

// A room corner: floor, back wall, left wall, and a "bush" of small spheres standing on the floor.
inline void RoomScene(std::vector<ScenePlane>* planes, std::vector<SceneSphere>* spheres) {
  *planes = {{Eigen::Vector3d(0, -1, 0), 1.0},                   // floor, 1 m below the camera
             {Eigen::Vector3d(0, 0, -1), 4.0},                   // back wall, 4 m ahead
             {Eigen::Vector3d(1, 0, -0.15).normalized(), 1.2}};  // left wall, turned a little
  spheres->clear();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.22, 0.22);
  for (int i = 0; i < 40; ++i) {
    spheres->push_back({Eigen::Vector3d(0.5 + u(rng), 0.55 + u(rng), 1.8 + u(rng)), 0.06});
  }
}

}  // namespace pdvo::test
