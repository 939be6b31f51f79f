// Annotation JSON (pdvo validate, show, train, evaluate, compare): parsed and checked against the format's rules.
#include "fuzz.h"
#include "pdvo/annotations/annotation.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pdvo::fuzz::WriteInput(data, size, ".json");
  pdvo::fuzz::ExpectOnlyPdvoErrors("ReadAnnotation", [&] {
    const pdvo::Annotation annotation = pdvo::ReadAnnotation(path);
    pdvo::ValidateOrThrow(annotation, path);
  });
  return 0;
}
