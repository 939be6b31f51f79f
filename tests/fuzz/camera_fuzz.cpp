// Camera YAML (pdvo vo -c, annotate-depth -c, a sequence's camera.yaml).
#include "fuzz.h"
#include "pdvo/common/camera.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pdvo::fuzz::WriteInput(data, size, ".yaml");
  pdvo::fuzz::ExpectOnlyPdvoErrors("Camera::Read", [&] { pdvo::Camera::Read(path).Check(path); });
  return 0;
}
