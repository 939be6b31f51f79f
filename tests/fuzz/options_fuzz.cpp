// Options YAML (--config of vo, synth, detect, train, annotate-depth, evaluate): every tool's options from the
// same file, each from its own section as the commands read them.
#include "fuzz.h"
#include "pdvo/annotations/depth_planes.h"
#include "pdvo/annotations/regions.h"
#include "pdvo/common/options.h"
#include "pdvo/infer/detector.h"
#include "pdvo/sim/synth.h"
#include "pdvo/train/trainer.h"
#include "pdvo/vo/odometry.h"

namespace {
template <class Options>
void Load(const std::string& path, const std::string& section) {
  pdvo::fuzz::ExpectOnlyPdvoErrors(section.c_str(), [&] {
    const Options options = pdvo::LoadOptions<Options>(path, section);
    pdvo::CheckOptionsOrThrow(options, section + " options");
  });
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pdvo::fuzz::WriteInput(data, size, ".yaml");
  Load<pdvo::vo::VoOptions>(path, "vo");
  Load<pdvo::sim::SynthOptions>(path, "synth");
  Load<pdvo::DetectorOptions>(path, "detector");
  Load<pdvo::TrainOptions>(path, "train");
  Load<pdvo::DepthPlaneOptions>(path, "annotate_depth");
  Load<pdvo::RegionSamplingOptions>(path, "regions");
  return 0;
}
