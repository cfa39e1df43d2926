// arpipe bench NAME: every benchmark (bench/), or, in a build without them, a message that says so.
#include <cstdio>

#include "apps/arpipe/commands.h"
#include "apps/cli/command_line.h"
#ifdef ARPIPE_WITH_BENCHMARKS
#include "bench/benchmarks.h"
#endif

namespace arpipe {

void add_bench_command(CLI::App& arpipe) {
  CLI::App* bench = arpipe.add_subcommand("bench", "run a benchmark: time against error (docs/BENCHMARKS.md)");
#ifdef ARPIPE_WITH_BENCHMARKS
  bench->require_subcommand(1);
  add_benchmarks(*bench);
#else
  bench->prefix_command();  // whatever follows is the benchmark's: not a usage error of its own
  cli::on_run(bench, [] {
    std::fputs("arpipe bench: this arpipe was built without the benchmarks (cmake -DARPIPE_BUILD_BENCH=OFF)\n", stderr);
    return 2;
  });
#endif
}

}  // namespace arpipe
