// `plslam synth`: render a synthetic stereo sequence with exact ground truth.
#include <chrono>
#include <iostream>
#include <memory>

#include <fmt/format.h>

#include "command_registry.h"
#include "plslam/core/error.h"
#include "plslam/core/log.h"
#include "plslam/synth/writer.h"

namespace {

struct Options {
  std::string out;
  std::string scene = "office";
  std::string format;  // default: the preset's own layout
  std::string preset = "euroc";
  int frames = 200;
  std::uint64_t seed = 1;
  bool loop = false;
  bool motion_blur = false;
  int threads = 0;
};

int run(const Options& o) {
  plslam::synth::SequenceOptions so;
  so.scene = plslam::synth::parse_scene_kind(o.scene);
  so.preset = plslam::synth::parse_preset(o.preset);
  so.frames = o.frames;
  so.seed = o.seed;
  so.loop = o.loop;
  so.motion_blur = o.motion_blur;
  const auto format = plslam::synth::parse_output_format(o.format.empty() ? o.preset : o.format);
  const plslam::synth::Sequence seq(so);
  spdlog::info("synth: {} scene, {} preset ({}x{} @ {} Hz, baseline {} m), {} frames, path {:.1f} m at {:.2f} m/s{}",
               o.scene, so.preset.name, so.preset.width, so.preset.height, so.preset.fps, so.preset.baseline,
               o.frames, seq.path().length(), seq.path().speed(), o.loop ? ", loop" : "");
  const auto start = std::chrono::steady_clock::now();
  std::size_t last = 0;
  plslam::synth::write_sequence(
      seq, o.out, format,
      [&](std::size_t done, std::size_t total) {
        if (done == total || done >= last + std::max<std::size_t>(1, total / 10)) {
          last = done;
          spdlog::info("synth: {}/{} frames", done, total);
        }
      },
      o.threads);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  spdlog::info("synth: wrote {} in {:.1f} s", o.out, s);
  return 0;
}

plslam::cli::CommandRegistration reg({"synth", "Render a synthetic stereo sequence with exact ground truth",
                                      [](CLI::App& sub) {
                                        auto o = std::make_shared<Options>();
                                        sub.add_option("--out", o->out, "Output folder")->required();
                                        sub.add_option("--scene", o->scene, "office|corridor|street")
                                            ->capture_default_str();
                                        sub.add_option("--frames", o->frames, "Number of stereo frames")
                                            ->capture_default_str()
                                            ->check(CLI::Range(2, 1000000));
                                        sub.add_option("--format", o->format, "euroc|kitti (default: the preset's)");
                                        sub.add_option("--preset", o->preset, "Camera preset: euroc|kitti")
                                            ->capture_default_str();
                                        sub.add_option("--seed", o->seed, "Seed for textures and motion")
                                            ->capture_default_str();
                                        sub.add_flag("--loop", o->loop, "Close a loop of >= 30 m and return to the start");
                                        sub.add_flag("--motion-blur", o->motion_blur, "Blur proportional to the motion");
                                        sub.add_option("--threads", o->threads, "Rendering threads (0: all cores)")
                                            ->capture_default_str();
                                        return std::function<int()>([o] { return run(*o); });
                                      }});

}  // namespace
