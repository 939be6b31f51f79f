// The rendered street the odometry's tests run on (pdvo_sim): 150 frames at 30 frames/s, 7 m of walking, with
// the truth of every frame: depth, the surface under each pixel, and the planes an exact detector would give.
#pragma once

#include <opencv2/imgproc.hpp>
#include <vector>

#include "pdvo/annotations/annotation.h"
#include "pdvo/eval/plane_match.h"
#include "pdvo/sim/renderer.h"
#include "pdvo/sim/synth.h"
#include "pdvo/vo/odometry.h"

namespace pdvo::vo {

struct Street {
  sim::SynthOptions options;
  sim::Street street;
  Trajectory walk;
  std::vector<cv::Mat> grey;
  std::vector<cv::Mat> depth;    // CV_32F, z in metres, 0 for the sky
  std::vector<cv::Mat> surface;  // CV_16S: the true surface (coplanar polygons share one), -1 for anything else
  Camera camera;
  std::vector<cv::Mat> colour;
  std::vector<std::vector<DetectedPlane>> planes;  // the frame's exact annotation (sim::AnnotateFrame)
};

// The frames of `walked` rendered with the renderer of `seed`, and their truth.
inline Street MakeStreet(const sim::SynthOptions& options, sim::WalkedStreet walked, uint64_t seed) {
  Street s;
  s.options = options;
  s.street = std::move(walked.street);
  s.walk = std::move(walked.walk);
  s.camera = options.MakeCamera();
  const sim::Renderer renderer(s.street, s.camera, options.render, seed);
  for (const StampedPose& pose : s.walk) {
    sim::RenderedFrame frame;
    renderer.Render({pose.world_from_cam}, pose.timestamp, s.grey.size(), &frame);
    cv::Mat grey;
    cv::cvtColor(frame.image, grey, cv::COLOR_BGR2GRAY);
    s.grey.push_back(grey);
    s.depth.push_back(frame.depth);
    s.colour.push_back(frame.image);
    s.planes.push_back(
        DetectedPlanes(sim::AnnotateFrame(s.street, frame, pose.world_from_cam, s.camera, ""), s.camera.width));
    cv::Mat surface(frame.id.size(), CV_16S);
    for (int y = 0; y < surface.rows; ++y) {
      for (int x = 0; x < surface.cols; ++x) {
        const int id = frame.id.at<int>(y, x);
        surface.at<int16_t>(y, x) = static_cast<int16_t>(id >= 0 ? s.street.planes.at(id).surface : -1);
      }
    }
    s.surface.push_back(surface);
  }
  return s;
}

// 150 frames at 30 frames/s: 7 m of walking.
inline const Street& TestStreet() {
  static const Street s = [] {
    const sim::SynthOptions options;
    sim::WalkedStreet walked;
    walked.street = sim::GenerateStreet(options.street, 40, 3);
    walked.walk = sim::WalkStreet(walked.street, options.walk, 150, 3);
    return MakeStreet(options, std::move(walked), 3);
  }();
  return s;
}

// A walk round a block whose first 150 frames turn the first corner (26 degrees by frame 32; `pdvo synth --seed 410
// -n 150 --set street.loop=true`).
inline const Street& CornerStreet() {
  static const Street s = [] {
    sim::SynthOptions options;
    options.street.loop = true;
    return MakeStreet(options, sim::MakeWalkedStreet(options, 150, 410), 410);
  }();
  return s;
}

// A plane's points lie on one true surface: in every frame, of the points of each plane in view (4 or more),
// the share on the plane's most common surface (by the rendered ids at their keyframe pixels).
// `points` (optional): how many plane points were counted.
inline double PurityOfPlanes(const Street& s, const VoOptions& options, PlaneDetector detector = {},
                             long* points = nullptr) {
  Odometry odometry(s.camera, options, nullptr, std::move(detector));
  PlanePurity purity;
  for (size_t k = 0; k < s.grey.size(); ++k) {
    odometry.Track(s.grey[k], s.walk[k].timestamp, s.colour[k]);
    for (const Observation& o : odometry.observations()) {
      if (o.plane < 0) continue;
      const size_t key = static_cast<size_t>(std::lround(o.keyframe_time * s.options.walk.fps));
      purity.Add(static_cast<int>(k), o.plane,
                 s.surface.at(key).at<int16_t>(cvRound(o.keyframe_pixel.y()), cvRound(o.keyframe_pixel.x())));
    }
  }
  return purity.Share(4, points);
}

}  // namespace pdvo::vo
