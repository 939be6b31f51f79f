// Model files (pdvo evaluate -m, detect -m, vo -m). Each input is read twice: as it is (the checksum refuses
// nearly every mutation) and sealed with a fresh checksum line, so that the fuzzer reaches the parser behind it.
#include "fuzz.h"
#include "pdvo/infer/model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pdvo::fuzz::WriteInput(data, size, ".yml");
  pdvo::fuzz::ExpectOnlyPdvoErrors("PlaneModel::Read", [&] { pdvo::PlaneModel::Read(path); });
  const std::string text(reinterpret_cast<const char*>(data), size);
  pdvo::fuzz::ExpectOnlyPdvoErrors("PlaneModel::FromYaml",
                                   [&] { pdvo::PlaneModel::FromYaml(pdvo::SealModelText(text), path); });
  return 0;
}
