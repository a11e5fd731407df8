// Each stage of a full-resolution preview shot on its own (Google Benchmark), on a real frame of
// the paper scene: where the issue #3 budget (10 s for 18 shots at 5472 x 3648) goes.
// Usage: dslr_stages_bench [--scale F] [benchmark flags]   (default scale 1: full resolution)
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "compiler/frontend.h"
#include "dslr/buffer_pool.h"
#include "dslr/develop.h"
#include "dslr/exposure.h"
#include "dslr/image_io.h"
#include "dslr/lens.h"
#include "dslr/optics.h"
#include "dslr/sensor.h"
#include "io/allocator.h"
#include "raster/rasterizer.h"
#include "scene/studio_scene.h"

namespace {

double g_scale = 1.0;

struct Fixture {
  rigc::ir::Scene scene;
  rigc::scene::StudioScene studio;
  rigc::raster::FrameRequest request;
  rigc::dslr::LinearFrame frame;  // radiance after exposure
  rigc::dslr::Intrinsics sensor;
};

Fixture& fixture() {
  static Fixture f = [] {
    Fixture out;
    std::ifstream in("scenes/paper-turntable.yaml");
    std::stringstream text;
    text << in.rdbuf();
    rigc::DiagnosticEngine diag;
    auto scene =
        rigc::compile_scene_text(text.str(), "scenes/paper-turntable.yaml", "scenes", diag);
    if (!scene) std::exit(1);
    out.scene = *scene;
    out.studio = rigc::scene::prepare_studio_scene(out.scene);
    const auto& shot = out.scene.shots[3];
    out.request.world_from_camera = shot.world_from_camera;
    out.request.turntable_angle_rad = shot.turntable_angle_rad;
    const auto geometry = rigc::dslr::render_geometry_for(out.scene.camera, g_scale);
    out.request.canvas = geometry;
    out.request.shadow_map_size = std::clamp(geometry.width / 2, 512, 2048);
    out.frame = rigc::raster::render_frame(out.scene, out.studio, out.request);
    rigc::dslr::expose_in_place(out.scene.camera, out.frame.rgb);
    out.sensor = rigc::dslr::sensor_intrinsics(out.scene.camera, g_scale);
    return out;
  }();
  return f;
}

void BM_RenderFrame(benchmark::State& state) {
  Fixture& f = fixture();
  rigc::raster::RasterTimings timings;
  for (auto _ : state) {
    rigc::dslr::LinearFrame frame =
        rigc::raster::render_frame(f.scene, f.studio, f.request, &timings);
    benchmark::DoNotOptimize(frame.rgb.data());
    rigc::dslr::recycle(std::move(frame.rgb));
    rigc::dslr::recycle(std::move(frame.depth_m));
    rigc::dslr::recycle(std::move(frame.mask));
  }
  using benchmark::Counter;
  state.counters["shadow_ms"] = Counter(timings.shadow_ms, Counter::kAvgIterations);
  state.counters["setup_ms"] = Counter(timings.setup_ms, Counter::kAvgIterations);
  state.counters["raster_ms"] = Counter(timings.raster_ms, Counter::kAvgIterations);
}

void BM_Exposure(benchmark::State& state) {
  Fixture& f = fixture();
  std::vector<float> work = f.frame.rgb;
  for (auto _ : state) rigc::dslr::expose_in_place(f.scene.camera, work);
}

// Argument 2: as the pipeline runs it on a preview frame, in place (sharp tiles untouched) with
// the tile ranges the renderer recorded; 1: the same into another buffer (every tile written);
// 0: into another buffer, the frame scanned for its ranges (other renderers).
void BM_DepthOfField(benchmark::State& state) {
  Fixture& f = fixture();
  std::vector<float> out(f.frame.rgb.size()), spare(f.frame.rgb.size());
  const double focus = f.scene.shots[3].focus_distance_m;
  rigc::dslr::DepthOfFieldOptions options;
  if (state.range(0) != 0) options.tile_ranges = &f.frame.tile_ranges;
  for (auto _ : state) {
    if (state.range(0) == 2) {
      state.PauseTiming();
      std::copy(f.frame.rgb.begin(), f.frame.rgb.end(), out.begin());
      state.ResumeTiming();
      rigc::dslr::apply_depth_of_field_in_place(f.scene.camera, focus, f.frame.intrinsics(), out,
                                                f.frame.depth_m, spare, options);
    } else {
      rigc::dslr::apply_depth_of_field(f.scene.camera, focus, f.frame.intrinsics(), f.frame.rgb,
                                       f.frame.depth_m, out, options);
    }
  }
}

void BM_Diffraction(benchmark::State& state) {
  Fixture& f = fixture();
  std::vector<float> work = f.frame.rgb;
  for (auto _ : state) rigc::dslr::apply_diffraction(f.scene.camera, f.frame.intrinsics(), work);
}

void BM_DistortionVignetting(benchmark::State& state) {
  Fixture& f = fixture();
  std::vector<float> storage(f.frame.rgb.size());
  for (auto _ : state) {
    auto image =
        rigc::dslr::warp_to_sensor(f.scene.camera, f.sensor, f.frame.intrinsics(), f.frame.rgb,
                                   f.frame.depth_m, f.frame.mask, std::move(storage));
    storage = std::move(image.rgb);
    rigc::dslr::recycle(std::move(image.depth_m));
    rigc::dslr::recycle(std::move(image.mask));
  }
}

// The sensor's input: the fixture's exposed frame, cut to the sensor's size.
std::vector<float> exposed_signal(Fixture& f) {
  std::vector<float> signal = f.frame.rgb;
  signal.resize(3 * static_cast<size_t>(f.sensor.width) * f.sensor.height);
  return signal;
}

void BM_SensorNoise(benchmark::State& state) {
  Fixture& f = fixture();
  const std::vector<float> signal = exposed_signal(f);
  std::vector<float> work = signal;
  int shot = 0;
  for (auto _ : state) {
    state.PauseTiming();
    std::copy(signal.begin(), signal.end(), work.begin());
    state.ResumeTiming();
    rigc::dslr::apply_sensor(
        f.scene.camera, rigc::dslr::view_of(work, f.sensor.width, f.sensor.height), {7, ++shot});
  }
}

// Noise and the 8-bit encoding as one pass, as the preview runs them.
void BM_SensorAndEncodeBytes(benchmark::State& state) {
  Fixture& f = fixture();
  const std::vector<float> signal = exposed_signal(f);
  const auto encoding = rigc::dslr::srgb_encoding({1.2, 1.0, 1.4}, 8);
  int shot = 0;
  for (auto _ : state) {
    auto bytes = rigc::dslr::apply_sensor_and_encode_bytes(
        f.scene.camera, rigc::dslr::view_of(signal, f.sensor.width, f.sensor.height), {7, ++shot},
        encoding);
    benchmark::DoNotOptimize(bytes.data());
    rigc::dslr::recycle(std::move(bytes));
  }
}

void BM_WhiteBalanceAndEncode(benchmark::State& state) {
  Fixture& f = fixture();
  std::vector<float> linear(3 * static_cast<size_t>(f.sensor.width) * f.sensor.height);
  std::copy_n(f.frame.rgb.begin(), linear.size(), linear.begin());
  std::vector<std::uint8_t> mask(linear.size() / 3);
  std::copy_n(f.frame.mask.begin(), mask.size(), mask.begin());
  for (auto _ : state) {
    const auto gains = rigc::dslr::white_balance_gains(f.scene.camera, linear, mask);
    auto encoded = rigc::dslr::encode_srgb(linear, gains, 8);
    benchmark::DoNotOptimize(encoded.data());
    rigc::dslr::recycle(std::move(encoded));
  }
}

// The writer thread's work: the 8-bit JPEG with EXIF, and the mask PNG.
void BM_WriteJpegAndMask(benchmark::State& state) {
  Fixture& f = fixture();
  rigc::dslr::DevelopResult result;
  result.width = f.sensor.width;
  result.height = f.sensor.height;
  result.bits = 8;
  std::vector<float> linear(3 * static_cast<size_t>(f.sensor.width) * f.sensor.height);
  std::copy_n(f.frame.rgb.begin(), linear.size(), linear.begin());
  result.encoded = rigc::dslr::encode_srgb(linear, {1, 1, 1}, 8);
  result.mask.assign(f.frame.mask.begin(), f.frame.mask.begin() + linear.size() / 3);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "rigc_write_bench";
  std::filesystem::create_directories(dir);
  double jpeg_ms = 0, mask_ms = 0;
  for (auto _ : state) {
    auto start = std::chrono::steady_clock::now();
    rigc::dslr::write_image(dir / "shot.jpg", result, f.scene.camera, nullptr);
    auto middle = std::chrono::steady_clock::now();
    rigc::dslr::write_mask(dir / "mask.png",
                           rigc::dslr::view_of(result.mask, result.width, result.height, 1),
                           nullptr);
    auto end = std::chrono::steady_clock::now();
    jpeg_ms += std::chrono::duration<double, std::milli>(middle - start).count();
    mask_ms += std::chrono::duration<double, std::milli>(end - middle).count();
  }
  state.counters["jpeg_ms"] = benchmark::Counter(jpeg_ms, benchmark::Counter::kAvgIterations);
  state.counters["mask_ms"] = benchmark::Counter(mask_ms, benchmark::Counter::kAvgIterations);
  std::filesystem::remove_all(dir);
}

BENCHMARK(BM_RenderFrame)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Exposure)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DepthOfField)->Arg(2)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Diffraction)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DistortionVignetting)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SensorNoise)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SensorAndEncodeBytes)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_WhiteBalanceAndEncode)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_WriteJpegAndMask)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  rigc::keep_freed_memory();
  for (int i = 1; i + 1 < argc; ++i) {
    if (!std::strcmp(argv[i], "--scale")) {
      g_scale = std::atof(argv[i + 1]);
      for (int j = i; j + 2 <= argc; ++j) argv[j] = argv[j + 2];
      argc -= 2;
      break;
    }
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
