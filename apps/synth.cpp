// pdvo synth: a synthetic urban street sequence with exact ground truth.
#include "pdvo/sim/synth.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/options.h"
#include "tool.h"

namespace pdvo::apps {

int RunSynth(int argc, char** argv) {
  CLI::App app(
      "Renders a procedurally generated urban street, walked by a hand-held camera at 1.4 m/s and 30 Hz, "
      "into a folder the TUM reader reads: images, metric depth, plane ids, exact poses, the world's "
      "planes and one annotation per frame. The same seed and options give the same files.",
      "pdvo synth");
  std::string out_dir, config_path, verbosity = "info";
  std::vector<std::string> overrides;
  uint64_t seed = 1;
  int frames = 300;
  app.add_option("--out,-o", out_dir, "Output folder")->required();
  app.add_option("--seed", seed, "Scene and walk seed")->capture_default_str()->check(NotNegative());
  app.add_option("--frames,-n", frames, "Number of frames")->capture_default_str()->check(CLI::PositiveNumber);
  AddConfigFlags(app, &config_path, &overrides, "Options YAML (section synth:, see sim/config/default.yaml)",
                 "street.loop=true --set width=640");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);

  const auto options = LoadToolOptions<sim::SynthOptions>(config_path, "synth", overrides);
  Progress progress("synth", static_cast<size_t>(frames));
  sim::WriteSynthSequence(out_dir, seed, frames, options, [&] { progress.Step(); });
  progress.Finish();
  PDVO_LOG(Info) << "wrote " << frames << " frames to " << out_dir;
  return 0;
}

}  // namespace pdvo::apps
