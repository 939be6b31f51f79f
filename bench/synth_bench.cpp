// Rendering speed and memory of the synthetic street: frames per second at 320x240 on one core (geometry only
// and fully shaded), and peak memory while rendering a long sequence (it must stay flat).
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "pdvo/common/logging.h"
#include "pdvo/sim/renderer.h"
#include "pdvo/sim/synth.h"

using pdvo::ResidentMiB;

int main(int argc, char** argv) {
  const int frames = argc > 1 ? std::atoi(argv[1]) : 2000;
  const bool help = argc > 1 && (std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help");
  if (help || frames <= 0) {
    std::fprintf(stderr, "usage: synth_bench [frames (default 2000)]\n");
    return help ? 0 : 2;
  }
  pdvo::sim::SynthOptions options;
  const pdvo::Camera camera = options.MakeCamera();
  const auto [street, walk] = pdvo::sim::MakeWalkedStreet(options, frames, 1);
  const pdvo::sim::Renderer renderer(street, camera, options.render, 1);
  std::printf("street: %zu planes, %zu objects, %.0f m; %d frames at %dx%d, one thread\n", street.planes.size(),
              street.blobs.size(), street.Length(), frames, camera.width, camera.height);
  pdvo::sim::RenderedFrame frame;
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  for (int i = 0; i < frames; ++i) renderer.RenderGeometry(walk[i].world_from_cam, &frame);
  const double geometry_s = std::chrono::duration<double>(Clock::now() - t0).count();
  double memory_first_tenth = 0;
  t0 = Clock::now();
  for (int i = 0; i < frames; ++i) {
    renderer.Render({walk[i].world_from_cam}, walk[i].timestamp, i, &frame);
    if (i == frames / 10) memory_first_tenth = ResidentMiB();
  }
  const double shaded_s = std::chrono::duration<double>(Clock::now() - t0).count();
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  std::printf("geometry only (depth + ids): %.1f frames/s\n", frames / geometry_s);
  std::printf("shaded (image + depth + ids): %.1f frames/s\n", frames / shaded_s);
  std::printf("resident memory: %.1f MiB after %d frames, %.1f MiB at the end; peak %.1f MiB\n", memory_first_tenth,
              frames / 10, ResidentMiB(), usage.ru_maxrss / 1024.0);
  return 0;
}
