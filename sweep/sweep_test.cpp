// The sweep's parts: the sweep file and its errors, the
// variants (grid, zip, names), compile errors at their lines, rank correlation, array lists.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "sweep/results.h"
#include "sweep/slurm_executor.h"
#include "sweep/sweep_spec.h"
#include "sweep/variants.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::sweep {
namespace {

using testing::read_text;
using testing::silence_diagnostics;
using testing::source_path;
using testing::TempDir;
using testing::write_text;

std::string all_diagnostics(DiagnosticEngine& diag) {
  std::string text;
  for (const auto& d : diag.diagnostics()) {
    text += d.loc.file + ":" + std::to_string(d.loc.line) + ":" + std::to_string(d.loc.col) + ": " +
            d.message + "\n";
  }
  return text;
}

TEST(SweepFile, ReadsAxesZipBackendScaleAndMeasures) {
  DiagnosticEngine diag;
  const auto spec = parse_sweep_text(
      "rigc-sweep: 1\nscene: scenes/paper.yaml\nvary:\n  camera.exposure.aperture: [f/4, f/8]\n"
      "  shots[0].turntable.steps: [12, 36]\n  shots[0].turntable.step: [30deg, 10deg]\n"
      "zip: [\"shots[0].turntable.steps\", \"shots[0].turntable.step\"]\nbackend: [preview, "
      "povray]\n"
      "scale: 0.1\nmeasure: [coverage, eval]\n",
      "/tmp/s/sweep.yaml", diag);
  ASSERT_TRUE(spec) << all_diagnostics(diag);
  EXPECT_EQ(spec->scene_path, "/tmp/s/scenes/paper.yaml");
  EXPECT_EQ(spec->name, "sweep");
  ASSERT_EQ(spec->axes.size(), 4u);
  EXPECT_TRUE(spec->axes[3].is_backend());
  EXPECT_DOUBLE_EQ(spec->scale, 0.1);
  EXPECT_TRUE(spec->coverage && spec->eval);
  const auto variants = expand_variants(*spec);
  ASSERT_EQ(variants.size(), 8u);  // 2 apertures x 2 zipped pairs x 2 backends
  EXPECT_EQ(variants[0].name, "aperture-f-4_steps-12_step-30deg_backend-preview");
  EXPECT_EQ(variants[1].backend, "povray");
  EXPECT_EQ(variants[2].values[1], "36");
  EXPECT_EQ(variants[2].values[2], "10deg");  // zipped with 36
}

TEST(SweepFile, ProblemsAreErrorsAtTheirLines) {
  DiagnosticEngine diag;
  silence_diagnostics(diag);
  EXPECT_FALSE(parse_sweep_text(
      "rigc-sweep: 1\nscene: a.yaml\nvary:\n  camera.exposure.aperture: [f/4, f/4]\n"
      "  shots[0].turntable.steps: [12]\nzip: [\"shots[0].turntable.steps\", backend]"
      "\nbackend: [preview, dali]\nmesure: [eval]\n",
      "s.yaml", diag));
  const std::string text = all_diagnostics(diag);
  EXPECT_THAT(text, HasSubstr("s.yaml:8:1: unknown key 'mesure' in the sweep file; did you mean "
                              "'measure'?"));
  EXPECT_THAT(text, HasSubstr("s.yaml:7:20: unknown backend 'dali'"));
  EXPECT_THAT(text, HasSubstr("s.yaml:4:35: 'f/4' is given twice"));
  EXPECT_THAT(text, HasSubstr("zipped axes need as many values"));
  DiagnosticEngine other;
  silence_diagnostics(other);
  EXPECT_FALSE(parse_sweep_text("rigc: 1\n", "s.yaml", other));
  EXPECT_THAT(all_diagnostics(other), HasSubstr("starts with `rigc-sweep: 1`"));
}

// Six configurations that are no grid: the zipped axes repeat values, their tuples do not.
TEST(SweepFile, ZippedAxesMayRepeatAValueButNotAConfiguration) {
  const std::string head =
      "rigc-sweep: 1\nscene: a.yaml\nvary:\n  camera.exposure.aperture: [f/8, f/13, f/13]\n"
      "  shots[0].turntable.steps: ";
  const std::string zip = "\nzip: [camera.exposure.aperture, \"shots[0].turntable.steps\"]\n";
  DiagnosticEngine diag;
  silence_diagnostics(diag);
  const auto spec = parse_sweep_text(head + "[18, 12, 36]" + zip, "s.yaml", diag);
  ASSERT_TRUE(spec) << all_diagnostics(diag);
  const auto variants = expand_variants(*spec);
  ASSERT_EQ(variants.size(), 3u);
  EXPECT_EQ(variants[2].name, "aperture-f-13_steps-36");

  DiagnosticEngine twice;
  silence_diagnostics(twice);
  EXPECT_FALSE(parse_sweep_text(head + "[18, 36, 36]" + zip, "s.yaml", twice));
  EXPECT_THAT(all_diagnostics(twice),
              HasSubstr("s.yaml:4:41: the zipped values (f/13, 36) are given twice"));
}

// A Cycles sweep at fewer samples than a final render: the count reaches every variant's render
// and its key, so changing it reruns them.
TEST(SweepFile, SamplesReachTheVariantsAndTheirKeys) {
  const std::string scene = source_path("scenes/paper-turntable.yaml");
  const std::string text =
      "rigc-sweep: 1\nscene: " + scene + "\nvary:\n  camera.exposure.aperture: [f/8]\n";
  auto key_with = [&](const std::string& samples_line) {
    DiagnosticEngine diag;
    silence_diagnostics(diag);
    const auto spec = parse_sweep_text(text + samples_line, "s.yaml", diag);
    EXPECT_TRUE(spec) << all_diagnostics(diag);
    std::vector<Variant> variants = expand_variants(*spec);
    EXPECT_TRUE(build_variants(*spec, read_text(scene), "/nonexistent", variants, diag));
    EXPECT_EQ(sweep_json(*spec, variants).at("samples"), spec->samples);
    return variants.at(0).key;
  };
  const std::string by_default = key_with(""), sixteen = key_with("samples: 16\n");
  EXPECT_NE(sixteen, by_default);
  EXPECT_EQ(key_with("samples: 16\n"), sixteen);
  // Converged sampling is a setting of its own.
  const std::string converged = key_with("samples: auto\n");
  EXPECT_NE(converged, by_default);
  EXPECT_NE(converged, sixteen);

  for (const std::string bad : {"samples: 0\n", "samples: 1.5\n", "samples: [16]\n"}) {
    DiagnosticEngine diag;
    silence_diagnostics(diag);
    EXPECT_FALSE(parse_sweep_text(text + bad, "s.yaml", diag));
    EXPECT_THAT(all_diagnostics(diag), HasSubstr("s.yaml:5:10: samples: must be a whole number"))
        << bad << all_diagnostics(diag);
  }
}

// The preview takes its samples as a square grid no finer than the sensor: a sweep that would
// give it others is an error at the samples line, naming the backend, before anything runs.
TEST(SweepFile, SamplesThePreviewCannotTakeAreRefusedAtTheirLine) {
  const std::string head = "rigc-sweep: 1\nscene: " + source_path("scenes/paper-turntable.yaml") +
                           "\nvary:\n  camera.exposure.aperture: [f/8]\n";
  const auto diagnostics = [&](const std::string& rest) {
    DiagnosticEngine diag;
    silence_diagnostics(diag);
    const bool parsed = parse_sweep_text(head + rest, "s.yaml", diag).has_value();
    return std::make_pair(parsed, all_diagnostics(diag));
  };
  const auto [square_ok, square] = diagnostics("backend: [preview, cycles]\nsamples: 32\n");
  EXPECT_FALSE(square_ok);
  EXPECT_THAT(square,
              HasSubstr("s.yaml:6:10: samples: the preview takes a square number of samples per "
                        "pixel (1, 4, 9, 16, ...), not 32 (backend preview)"));
  const auto [fine_ok, fine] = diagnostics("scale: 0.5\nsamples: 16\n");
  EXPECT_FALSE(fine_ok);
  EXPECT_THAT(fine,
              HasSubstr("s.yaml:6:10: samples: 16 samples per pixel at scale 0.5 would render the "
                        "preview larger than the sensor"));
  EXPECT_TRUE(diagnostics("backend: cycles\nscale: 0.5\nsamples: 32\n").first);
}

TEST(SweepFile, FolderNamesAreSanitised) {
  EXPECT_EQ(folder_name("../../etc/passwd"), "..-..-etc-passwd");
  EXPECT_EQ(folder_name(".."), "_..");
  EXPECT_EQ(folder_name(""), "_");
  EXPECT_EQ(folder_name("a b$(x)`y`"), "a-b--x--y-");
  EXPECT_EQ(folder_name(std::string(100, 'x')).size(), 40u);
}

TEST(SweepVariants, AVariantThatDoesNotCompileIsAnErrorAtItsValueAndTheScenesLine) {
  TempDir dir;
  const std::string scene = source_path("scenes/paper-turntable.yaml");
  DiagnosticEngine diag;
  silence_diagnostics(diag);
  const std::string sweep_text =
      "rigc-sweep: 1\nscene: " + scene + "\nvary:\n  camera.exposure.aperture: [f/8, f/0.5]\n";
  const auto spec = parse_sweep_text(sweep_text, dir.file("s.yaml"), diag);
  ASSERT_TRUE(spec) << all_diagnostics(diag);
  std::vector<Variant> variants;
  EXPECT_FALSE(build_variants(*spec, read_text(scene), dir.path() / "out", variants, diag));
  const std::string text = all_diagnostics(diag);
  EXPECT_THAT(text,
              HasSubstr(dir.file("s.yaml") + ":4:35: variant 'aperture-f-0.5' does not compile "
                                             "(camera.exposure.aperture = f/0.5): aperture f/0.5"));
  EXPECT_THAT(text, HasSubstr(scene + ":23:"));               // the scene's line
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));  // nothing ran
}

TEST(SweepVariants, AMissingPathIsAnErrorAtTheAxis) {
  const std::string scene = source_path("scenes/paper-turntable.yaml");
  DiagnosticEngine diag;
  silence_diagnostics(diag);
  const auto spec = parse_sweep_text(
      "rigc-sweep: 1\nscene: " + scene + "\nvary:\n  camera.exposure.isoo: [100]\n", "s.yaml",
      diag);
  ASSERT_TRUE(spec);
  std::vector<Variant> variants;
  EXPECT_FALSE(build_variants(*spec, read_text(scene), "/nonexistent", variants, diag));
  EXPECT_THAT(all_diagnostics(diag), HasSubstr("s.yaml:4:3: 'camera.exposure' has no key 'isoo'"));
}

TEST(SweepVariants, AModelFileEditedInPlaceChangesTheVariantsKey) {
  TempDir dir;
  write_text(dir.file("box.obj"),
             "v 0 0 0\nv 0.2 0 0\nv 0 0.2 0\nv 0 0 0.2\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  std::string scene_text = read_text(source_path("scenes/paper-turntable.yaml"));
  const std::string primitive = "primitive: {shape: statue, detail: 6, seed: 7}";
  scene_text.replace(scene_text.find(primitive), primitive.size(), "mesh: box.obj");
  write_text(dir.file("scene.yaml"), scene_text);
  DiagnosticEngine diag;
  silence_diagnostics(diag);
  const auto spec = parse_sweep_text(
      "rigc-sweep: 1\nscene: scene.yaml\nvary:\n  "
      "camera.exposure.aperture: [f/8, f/11]\n",
      dir.file("s.yaml"), diag);
  ASSERT_TRUE(spec) << all_diagnostics(diag);
  auto keys = [&] {
    std::vector<Variant> variants = expand_variants(*spec);
    EXPECT_TRUE(build_variants(*spec, scene_text, dir.path() / "out", variants, diag))
        << all_diagnostics(diag);
    return std::vector<std::string>{variants.at(0).key, variants.at(1).key};
  };
  const auto before = keys();
  EXPECT_NE(before[0], before[1]);
  EXPECT_EQ(keys(), before);  // the same inputs, the same keys
  write_text(dir.file("box.obj"),
             "v 0 0 0\nv 0.3 0 0\nv 0 0.2 0\nv 0 0 0.2\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  const auto after = keys();
  EXPECT_NE(after[0], before[0]);
  EXPECT_NE(after[1], before[1]);
}

// 64 axes of two values make 2^64 variants: the count saturates past the bound instead of
// overflowing to none.
TEST(SweepVariants, AGridPastTheBoundIsCountedAsPastIt) {
  SweepSpec spec;
  for (int a = 0; a < 64; ++a) {
    spec.axes.push_back({"camera.axis" + std::to_string(a), {}, {{"1", {}}, {"2", {}}}});
  }
  EXPECT_EQ(expand_variants(spec).size(), 1001u);
}

TEST(SweepResults, PlotAxesTickAtRoundNumbers) {
  const AxisTicks f = nice_ticks(-0.0066, 0.5329);
  EXPECT_EQ(f.values, (std::vector<double>{-0.2, 0.0, 0.2, 0.4, 0.6}));
  EXPECT_EQ(f.decimals, 1);
  const AxisTicks points = nice_ticks(640, 26000);
  EXPECT_EQ(points.values.front(), 0);
  EXPECT_EQ(points.values.back(), 30000);
  EXPECT_EQ(points.decimals, 0);
  const AxisTicks flat = nice_ticks(0.95, 0.95);
  EXPECT_GE(flat.values.size(), 2u);
}

TEST(SweepResults, SpearmanRanksWithTies) {
  EXPECT_NEAR(*spearman({1, 2, 3, 4}, {10, 20, 30, 40}), 1.0, 1e-12);
  EXPECT_NEAR(*spearman({1, 2, 3, 4}, {4, 3, 2, 1}), -1.0, 1e-12);
  // Ranks (1, 2.5, 2.5, 4) against (1, 2, 3, 4): rho = 4.5 / sqrt(4.5 * 5).
  EXPECT_NEAR(*spearman({1, 2, 2, 3}, {1, 2, 3, 4}), 4.5 / std::sqrt(4.5 * 5), 1e-12);
  EXPECT_FALSE(spearman({1, 1, 1}, {1, 2, 3}));
  EXPECT_FALSE(spearman({1}, {1}));
}

TEST(SweepSlurm, ArrayListsAreRanges) {
  EXPECT_EQ(array_list({3, 0, 1, 2, 7, 9, 10}), "0-3,7,9-10");
  EXPECT_EQ(array_list({5}), "5");
}

}  // namespace
}  // namespace rigc::sweep
