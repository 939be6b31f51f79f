// Writing a synthetic street sequence: images, metric depth, plane ids, exact poses and annotations, in a folder
// the TUM reader reads. The same seed and options give the same files, byte for byte.
//
// Folder layout: rgb/NNNNNN.png, depth/NNNNNN.png (16-bit, kSynthDepthScale per metre, given as depth_scale in
// camera.yaml; 0 = sky or beyond 32.7 m),
// planes/NNNNNN.png (16-bit: plane id + 1, 0 = not a plane), annotations/NNNNNN.json (every visible plane with
// its camera-frame normal; clutter and sky as non-plane), rgb.txt, depth.txt, groundtruth.txt (TUM),
// camera.yaml, planes.json (each world plane: id, material, normal, distance, polygon) and synth.yaml (the
// options used).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "pdvo/annotations/annotation.h"
#include "pdvo/common/camera.h"
#include "pdvo/sim/renderer.h"
#include "pdvo/sim/street.h"

namespace pdvo::sim {

// Depth image units per metre: half millimetres, up to 32.7 m.
inline constexpr double kSynthDepthScale = 2000.0;

struct SynthOptions {
  int width = 320, height = 240;  // pixels
  double fx = 0, fy = 0;          // pixels; 0: a 60-degree horizontal field of view
  double cx = -1, cy = -1;        // pixels; negative: the image centre
  StreetOptions street;
  WalkOptions walk;
  RenderOptions render;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("width", self.width);
    visit("height", self.height);
    visit("fx", self.fx);
    visit("fy", self.fy);
    visit("cx", self.cx);
    visit("cy", self.cy);
    visit("street", self.street);
    visit("walk", self.walk);
    visit("render", self.render);
  }
  bool Check() const;
  bool operator==(const SynthOptions&) const = default;
  // The camera these options describe.
  Camera MakeCamera() const;
};

// The annotation of one rendered frame: every visible geometric plane (coplanar polygons, such as the road and
// pavements, are one plane) with its normal in the camera frame; clutter and sky as non-plane.
Annotation AnnotateFrame(const Street& street, const RenderedFrame& frame, const Rigid3d& world_from_cam,
                         const Camera& camera, const std::string& image_path);

// A street long enough for a walk of `frames` frames with 30 m to spare (the view ahead stays on the street), and
// that walk: what the synthetic sequence of this seed shows.
struct WalkedStreet {
  Street street;
  Trajectory walk;
};
WalkedStreet MakeWalkedStreet(const SynthOptions& options, int frames, uint64_t seed);

// The exact annotation of the renderer's view from `world_from_cam` (Renderer::RenderGeometry, then
// AnnotateFrame with the renderer's street and camera): what a perfect plane detector would say, the oracle of the
// odometry's benchmarks.
Annotation AnnotateView(const Renderer& renderer, const Rigid3d& world_from_cam);

// Renders `frames` frames and writes the folder (staged: nothing is left behind on failure). `on_frame` is
// called after each frame, for progress.
void WriteSynthSequence(const std::string& out_dir, uint64_t seed, int frames, const SynthOptions& options,
                        const std::function<void()>& on_frame = {});

}  // namespace pdvo::sim
