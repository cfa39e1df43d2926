// arpipe: the utility beside the daemon: inspect and replay recordings, simulate captures, check configs.
#include <csignal>
#include <cstdio>
#include <string>

#include "apps/arpipe/commands.h"
#include "core/log.h"
#include "core/frame_memory.h"

namespace {

constexpr const char* kUsage = R"(usage: arpipe COMMAND [ARGS]

commands:
  inspect DIR                        summary of a recording: frames, format, timing, drops
  replay DIR [--config FILE] [--set KEY=VALUE]...
                                     run the pipeline on a recording as fast as possible
  simulate --scene FILE --out DIR [--frames N] [--seed S] [--threads N] [--samples N]
                                     render a simulator scene (configs/sim/) into a
                                     recording with exact ground truth
  calib (--images GLOB | --recording DIR) --board FILE --out CAMERA.cameramodel [--lensmodel NAME]
                                     calibrate a camera's lens with mrcal from views of a
                                     board (configs/boards/), with a report
  board FILE --out BOARD.png [--dpi N]
                                     draw a board file's printable picture
  bench blur [--capture DIR | --scene FILE] [--out DIR] [--frames N] [--reference-samples N]
                                     motion-blur methods: time against error (PSNR, SSIM)
                                     vs the converged reference and the simulator's truth
  bench shadows [--frames N]         shadow methods and map sizes: time against the error of
                                     the shadow on the ground vs the simulator's ray tracing
  bench sh [--samples N] [--seed S]  spherical harmonics: reconstruction error against bands,
                                     irradiance error of 9 coefficients vs Monte Carlo
  bench prt [OPTIONS]                PRT bake: time against samples against the error vs a
                                     ray-traced reference; run-time cost vs Lambert shading
  sh --probe FILE --layout L [--bands N] [--normal X,Y,Z]... [--reconstruct OUT]
                                     an HDR light probe's SH coefficients and irradiance
  bake MODEL [--kind K] [--bands N] [--samples N] [--cache-dir DIR] [--force]
                                     precompute a mesh's radiance transfer (PRT) into the cache
  sun --lat DEG --lon DEG --time ISO8601 [--alt M] [--delta-t S] [--pressure MBAR] [--temperature C]
      [--heading DEG] [--declination DEG] [--algorithm spa|psa|both]
                                     the sun's azimuth, elevation and direction (ENU, anchor
                                     frame) for a place and time (NREL SPA and/or PSA)
  cameras [DEVICE]...                every camera V4L2 and libcamera see: formats, sizes, rates,
                                     controls, and the config key that selects it
  record --camera CAMERA --out DIR [--frames N | --seconds S] [--width W --height H] [--fps F]
         [--format F] [--exposure-us US] [--gain G] [--camera-model FILE] [--config FILE]
                                     record a live camera (CAMERA: /dev/videoN, v4l2:PATH or
                                     libcamera:ID|INDEX) with its exposure metadata
  config --defaults                  print a config with every key at its default
  config --check FILE                validate a config file
)";

}  // namespace

int main(int argc, char** argv) {
  arpipe::keep_frame_memory_resident();
  arpipe::log::set_program_name("arpipe");
  std::signal(SIGPIPE, SIG_IGN);  // a reader that goes away (a FIFO output) is EPIPE for the sink, not death
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::string command = argv[1];
  const arpipe::Args args(argv + 2, argv + argc);
  if (command == "inspect") return arpipe::run_inspect(args);
  if (command == "replay") return arpipe::run_replay(args);
  if (command == "simulate") return arpipe::run_simulate(args);
  if (command == "config") return arpipe::run_config(args);
  if (command == "calib") return arpipe::run_calib(args);
  if (command == "board") return arpipe::run_board(args);
  if (command == "bench") return arpipe::run_bench(args);
  if (command == "sun") return arpipe::run_sun(args);
  if (command == "cameras") return arpipe::run_cameras(args);
  if (command == "record") return arpipe::run_record(args);
  if (command == "sh") return arpipe::run_sh(args);
  if (command == "bake") return arpipe::run_bake(args);
  std::fprintf(stderr, "arpipe: unknown command '%s'\n%s", command.c_str(), kUsage);
  return 2;
}
