// Every backend that hands scripts to another program renders a scene whose mesh path, scene name
// and output folder would break out of any unescaped string, and nothing in them runs.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "backends/registry.h"
#include "run/run_loop.h"
#include "tests/hostile_scene.h"
#include "tests/test_support.h"

namespace rigc::backends {
namespace {

namespace fs = std::filesystem;

TEST(Backends, HostilePathsRenderWithoutRunningAnything) {
  for (const BackendEntry& entry : registry()) {
    const std::unique_ptr<run::Backend> backend = entry.make();
    if (!backend->emits_scripts()) continue;
    SCOPED_TRACE(entry.name);
    std::string error;
    RIGC_REQUIRE_TOOL(backend->available(&error), entry.name);
    testing::TempDir dir;
    const ir::Scene scene = testing::hostile_scene(dir);
    ASSERT_FALSE(scene.shots.empty());
    run::RunOptions options;
    options.output_dir = dir.path() / "out \"'; touch PWNED #";
    options.settings.scale = 0.02;
    options.settings.samples = 1;
    std::ostringstream log;
    EXPECT_EQ(run::run_backend(scene, *backend, options, log), 0) << log.str();
    EXPECT_TRUE(fs::exists(options.output_dir / "images" / "shot_000.jpg"));
    EXPECT_TRUE(fs::exists(options.output_dir / "masks" / "shot_000.png"));
    EXPECT_FALSE(testing::pwned_anywhere(dir.path()));
  }
}

}  // namespace
}  // namespace rigc::backends
