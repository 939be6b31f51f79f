// Uses an installed pdvo: renders a synthetic street, recognises a region of its first frame with the shipped
// model, and tracks ten frames with the odometry. Exits 1 if a result is not what it must be.
#include <cstdio>

#include "pdvo/infer/model.h"
#include "pdvo/infer/recogniser.h"
#include "pdvo/sim/renderer.h"
#include "pdvo/sim/synth.h"
#include "pdvo/vo/frames.h"
#include "pdvo/vo/odometry.h"

int main() {
  const pdvo::sim::SynthOptions options;
  const pdvo::Camera camera = options.MakeCamera();
  const pdvo::sim::Street street = pdvo::sim::GenerateStreet(options.street, 40, 7);
  const pdvo::Trajectory walk = pdvo::sim::WalkStreet(street, options.walk, 10, 7);
  const pdvo::sim::Renderer renderer(street, camera, options.render, 7);
  const pdvo::vo::FramePreparer preparer(camera, 320);
  pdvo::vo::Odometry odometry(preparer.working_camera(), pdvo::vo::VoOptions());
  cv::Mat first;
  for (size_t k = 0; k < walk.size(); ++k) {
    pdvo::sim::RenderedFrame frame;
    renderer.Render({walk[k].world_from_cam}, walk[k].timestamp, k, &frame);
    if (k == 0) first = frame.image;
    odometry.Track(preparer.Prepare(frame.image).grey, walk[k].timestamp);
  }
  const pdvo::Recogniser recogniser(pdvo::PlaneModel::Read(PDVO_MODEL));
  const pdvo::ImageWords words = recogniser.Describe(first);
  const pdvo::RegionPrediction p =
      recogniser.Recognise(words, {cv::Rect(0, first.rows / 2, first.cols, first.rows / 2), {}});
  std::printf(
      "pdvo consumer: the lower half of the first frame is a plane with probability %.2f; %zu poses, the "
      "last at %.3f %.3f %.3f\n",
      p.plane_probability, odometry.trajectory().size(), odometry.world_from_cam().translation.x(),
      odometry.world_from_cam().translation.y(), odometry.world_from_cam().translation.z());
  const bool ok = p.valid && p.plane_probability >= 0 && p.plane_probability <= 1 &&
                  odometry.trajectory().size() == 10 && odometry.world_from_cam().translation.allFinite();
  return ok ? 0 : 1;
}
