// arpipe bench NAME: the benchmarks that run the real pipeline parts (more live in build/bench/).
#include <fmt/format.h>

#include <cstdio>

#include "apps/arpipe/commands.h"

namespace arpipe {

int run_bench(const Args& args) {
  if (!args.empty() && args[0] == "blur") return run_bench_blur(Args(args.begin() + 1, args.end()));
  if (!args.empty() && args[0] == "shadows") return run_bench_shadows(Args(args.begin() + 1, args.end()));
  if (!args.empty() && args[0] == "sh") return run_bench_sh(Args(args.begin() + 1, args.end()));
  if (!args.empty() && args[0] == "prt") return run_bench_prt(Args(args.begin() + 1, args.end()));
  std::fputs("usage: arpipe bench blur|shadows|sh|prt [OPTIONS]   (arpipe bench NAME --help for the options)\n", stderr);
  return 2;
}

}  // namespace arpipe
