// Replays inputs through the readers' fuzz target (readers_fuzz.cpp) without
// libFuzzer: every file named on the command line, and every file in every
// directory named, runs once through LLVMFuzzerTestOneInput. Built with the
// sanitizer build's compiler and flags as the test `fuzz.corpus_replay`, so
// that the seeds and every crash input kept in fuzz/corpus stay regression
// tests of `make test`; the fuzzing itself (new inputs, minutes of it) is
// `make fuzz`.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv);
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

bool replay(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "fuzz replay: cannot read %s\n", file.c_str());
    return false;
  }
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  LLVMFuzzerInitialize(&argc, &argv);
  int replayed = 0;
  for (int i = 1; i < argc; ++i) {
    const std::filesystem::path path = argv[i];
    if (std::filesystem::is_directory(path)) {
      for (const auto& entry : std::filesystem::directory_iterator(path)) {
        if (!entry.is_regular_file()) continue;
        if (!replay(entry.path())) return 1;
        ++replayed;
      }
    } else {
      if (!replay(path)) return 1;
      ++replayed;
    }
  }
  if (replayed == 0) {
    std::fprintf(stderr, "fuzz replay: no input given (a file or a directory of inputs)\n");
    return 1;
  }
  std::printf("fuzz replay: %d inputs through the readers, no defect\n", replayed);
  return 0;
}
