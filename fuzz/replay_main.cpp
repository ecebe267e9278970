/*
 * Replays a fuzz target's corpus without libFuzzer, so that the normal (gcc) build and the
 * sanitizer build run every kept input under CTest:
 *   fuzz_pcd_replay DIR_OR_FILE...
 * Each file's bytes go to LLVMFuzzerTestOneInput once; a crash or trap fails the test, and the
 * driver reports how many inputs it ran (0 inputs is an error, so a missing corpus cannot pass).
 */
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

bool
replay(const std::filesystem::path& file)
{
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "replay: cannot read %s\n", file.c_str());
    return false;
  }
  const std::vector<char> bytes{std::istreambuf_iterator<char>(in),
                                std::istreambuf_iterator<char>()};
  std::printf("replay: %s (%zu bytes)\n", file.c_str(), bytes.size());
  std::fflush(stdout);
  LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  return true;
}

} // namespace

int
main(int argc, char** argv)
{
  namespace fs = std::filesystem;
  std::size_t count = 0;
  for (int i = 1; i < argc; ++i) {
    std::error_code error;
    if (fs::is_directory(argv[i], error)) {
      std::vector<fs::path> files;
      for (const auto& entry : fs::directory_iterator(argv[i]))
        if (entry.is_regular_file())
          files.push_back(entry.path());
      std::sort(files.begin(), files.end());
      for (const auto& f : files)
        count += replay(f) ? 1 : 0;
    }
    else if (fs::is_regular_file(argv[i], error))
      count += replay(argv[i]) ? 1 : 0;
    else {
      std::fprintf(stderr, "replay: %s is neither a file nor a directory\n", argv[i]);
      return 2;
    }
  }
  std::printf("replay: %zu inputs ran\n", count);
  return count > 0 ? 0 : 1;
}
