// A main() for the libFuzzer targets where libFuzzer is not linked (the GCC builds that ctest
// runs): replays every seed and reproducer, then, for a bounded time, feeds seeded random mutations
// of them. Not coverage-guided (that is scripts/fuzz.sh with clang's libFuzzer); it keeps the CI
// sanitizer build fuzzing every parser on every change, reproducibly (same seed, same inputs).
//
// Usage: TARGET [--seconds=S] [--seed=N] [--max-len=BYTES] FILE_OR_DIR...
// Exit status: 0 when nothing crashed; a crash is the sanitizers' report and abort, after the input
// is written to $ARPIPE_FUZZ_ARTIFACTS (default: the working directory) as crash-<target>-<n>.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <string_view>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
// The sanitizers' runtime has it; weak, so the plain (unsanitized) build links without it.
extern "C" void __sanitizer_set_death_callback(void (*callback)()) __attribute__((weak));

namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<uint8_t>;

struct Options {
  double seconds = 0;
  uint64_t seed = 1;
  size_t max_len = 0;  // 0: twice the largest seed, at least 4096
  std::vector<fs::path> inputs;
};

// The input being run, for the death callback: a crash leaves it on disk to replay.
const Bytes* g_current = nullptr;
std::string g_artifact;

void save_current_input() {
  if (g_current == nullptr || g_artifact.empty()) return;
  std::ofstream out(g_artifact, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(g_current->data()), std::streamsize(g_current->size()));
  std::fprintf(stderr, "standalone fuzz driver: the input is in %s\n", g_artifact.c_str());
}

void run_one(const Bytes& input) {
  g_current = &input;
  LLVMFuzzerTestOneInput(input.data(), input.size());
  g_current = nullptr;
}

Bytes read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void collect(const fs::path& path, std::vector<fs::path>& files) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    for (const auto& entry : fs::recursive_directory_iterator(path, ec))
      if (entry.is_regular_file(ec)) files.push_back(entry.path());
  } else if (fs::is_regular_file(path, ec)) {
    files.push_back(path);
  }  // a seed folder that does not exist is skipped: the modules' corpora are optional
}

// Values that sit at the edges of the integer types: where size checks overflow.
constexpr std::array<uint64_t, 10> kInteresting = {0,          1,          0x7f,       0xff,       0x7fff,
                                                   0xffff,     0x7fffffff, 0xffffffff, 1ull << 63, ~0ull};

// One of libFuzzer's simple mutations, chosen at random; `other` is another seed to splice in.
void mutate(Bytes& data, const Bytes& other, size_t max_len, std::mt19937_64& rng) {
  auto below = [&](size_t n) { return n == 0 ? size_t{0} : size_t(rng() % n); };
  switch (rng() % 8) {
    case 0:  // flip a bit
      if (!data.empty()) data[below(data.size())] ^= uint8_t(1u << (rng() % 8));
      break;
    case 1:  // set a byte
      if (!data.empty()) data[below(data.size())] = uint8_t(rng());
      break;
    case 2: {  // insert random bytes
      const size_t n = 1 + below(8), at = below(data.size() + 1);
      for (size_t i = 0; i < n; ++i) data.insert(data.begin() + std::ptrdiff_t(at), uint8_t(rng()));
      break;
    }
    case 3: {  // erase a range
      if (data.empty()) break;
      const size_t at = below(data.size()), n = 1 + below(std::min<size_t>(data.size() - at, 64));
      data.erase(data.begin() + std::ptrdiff_t(at), data.begin() + std::ptrdiff_t(at + n));
      break;
    }
    case 4: {  // duplicate a range
      if (data.empty()) break;
      const size_t at = below(data.size()), n = 1 + below(std::min<size_t>(data.size() - at, 64));
      const Bytes copy(data.begin() + std::ptrdiff_t(at), data.begin() + std::ptrdiff_t(at + n));
      data.insert(data.begin() + std::ptrdiff_t(below(data.size() + 1)), copy.begin(), copy.end());
      break;
    }
    case 5: {  // overwrite with an interesting integer, 1 to 8 bytes, either byte order
      if (data.empty()) break;
      const uint64_t value = kInteresting[below(kInteresting.size())];
      const size_t width = size_t(1) << below(4), at = below(data.size());
      const bool big = rng() % 2;
      for (size_t i = 0; i < width && at + i < data.size(); ++i)
        data[at + i] = uint8_t(value >> (8 * (big ? width - 1 - i : i)));
      break;
    }
    case 6: {  // write an interesting number as decimal text (text formats: sizes, counts, indices)
      const std::string text = std::to_string(int64_t(kInteresting[below(kInteresting.size())]));
      const size_t at = below(data.size() + 1);
      data.insert(data.begin() + std::ptrdiff_t(at), text.begin(), text.end());
      break;
    }
    default: {  // splice: this input's head with the other's tail
      if (other.empty()) break;
      const size_t cut = below(data.size() + 1), from = below(other.size());
      data.resize(cut);
      data.insert(data.end(), other.begin() + std::ptrdiff_t(from), other.end());
      break;
    }
  }
  if (data.size() > max_len) data.resize(max_len);
}

bool parse_options(int argc, char** argv, Options& options) {
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    auto value = [&](std::string_view name) { return std::string(arg.substr(name.size())); };
    if (arg.rfind("--seconds=", 0) == 0) {
      options.seconds = std::strtod(value("--seconds=").c_str(), nullptr);
    } else if (arg.rfind("--seed=", 0) == 0) {
      options.seed = std::strtoull(value("--seed=").c_str(), nullptr, 10);
    } else if (arg.rfind("--max-len=", 0) == 0) {
      options.max_len = std::strtoull(value("--max-len=").c_str(), nullptr, 10);
    } else if (arg.rfind("--", 0) == 0) {
      std::fprintf(stderr, "standalone fuzz driver: unknown option %s\n", argv[i]);
      return false;
    } else {
      options.inputs.emplace_back(arg);
    }
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (!parse_options(argc, argv, options)) return 2;
  const char* artifacts = std::getenv("ARPIPE_FUZZ_ARTIFACTS");
  g_artifact = (fs::path(artifacts != nullptr ? artifacts : ".") /
                ("crash-" + fs::path(argv[0]).filename().string() + "-" + std::to_string(options.seed)))
                   .string();
  if (__sanitizer_set_death_callback != nullptr) __sanitizer_set_death_callback(save_current_input);

  std::vector<fs::path> files;
  for (const fs::path& input : options.inputs) collect(input, files);
  std::sort(files.begin(), files.end());
  std::vector<Bytes> seeds;
  size_t largest = 0;
  for (const fs::path& file : files) {
    seeds.push_back(read_file(file));
    largest = std::max(largest, seeds.back().size());
    run_one(seeds.back());
  }
  std::printf("%zu seed and reproducer inputs ran\n", seeds.size());
  if (options.seconds <= 0) return 0;
  if (seeds.empty()) seeds.emplace_back();
  const size_t max_len = options.max_len > 0 ? options.max_len : std::max<size_t>(4096, 2 * largest);

  std::mt19937_64 rng(options.seed);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(options.seconds);
  uint64_t executions = 0;
  while (std::chrono::steady_clock::now() < deadline) {
    Bytes input = seeds[rng() % seeds.size()];
    const size_t rounds = 1 + rng() % 4;  // stacked mutations, as libFuzzer does
    for (size_t r = 0; r < rounds; ++r) mutate(input, seeds[rng() % seeds.size()], max_len, rng);
    run_one(input);
    ++executions;
  }
  std::printf("%llu mutated inputs ran in %.0f s (seed %llu), no crash\n", static_cast<unsigned long long>(executions),
              options.seconds, static_cast<unsigned long long>(options.seed));
  return 0;
}
