// The reference check through the studio's API: POV-Ray renders the current view in the
// background into the studio's run folder, beside the preview's frame; it can be cancelled, and
// a failing renderer is reported with its log.
#include "studio/reference_check.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <stdlib.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "io/child_processes.h"
#include "studio/server.h"
#include "studio/server_test_support.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::studio {
namespace {

namespace fs = std::filesystem;

class StudioReference : public StudioServerTest {
 protected:
  httplib::Result start(const std::string& backend, int width) {
    return client_->Post("/api/reference",
                         nlohmann::json{{"backend", backend}, {"width", width}}.dump(),
                         "application/json");
  }
  // The status once it is no longer running (or after `seconds`).
  nlohmann::json wait(double seconds) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    nlohmann::json status;
    do {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      status = nlohmann::json::parse(client_->Get("/api/reference")->body);
    } while (status["state"] == "running" && std::chrono::steady_clock::now() < until);
    return status;
  }
};

TEST_F(StudioReference, PovrayRendersTheViewBesideThePreviewWhileTheLiveViewGoesOn) {
  RIGC_REQUIRE_TOOL(find_executable("povray"), "povray");
  EXPECT_EQ(client_->Get("/api/reference/image")->status, 404);  // none yet
  const auto res = start("povray", 96);
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(start("povray", 96)->status, 422);  // one at a time
  // The live view does not wait for the reference.
  EXPECT_EQ(client_->Get("/api/frame?width=200")->status, 200);
  const nlohmann::json status = wait(240);
  ASSERT_EQ(status["state"], "done") << status.dump(1);
  EXPECT_EQ(status["width"].get<int>(), 96);
  EXPECT_EQ(status["height"].get<int>(), 64);
  EXPECT_TRUE(fs::exists(dir_.path() / "run" / "povray" / "images" / "shot_000.jpg"));
  EXPECT_TRUE(fs::exists(dir_.path() / "run" / "povray" / "manifest.json"));
  for (const char* which : {"reference", "preview"}) {
    const auto image = client_->Get((std::string("/api/reference/image?which=") + which).c_str());
    ASSERT_TRUE(image && image->status == 200) << which;
    EXPECT_EQ(image->get_header_value("Content-Type"), "image/jpeg");
    EXPECT_EQ(static_cast<unsigned char>(image->body[0]), 0xFF) << which;
    EXPECT_GT(image->body.size(), 500u) << which;
  }
}

TEST_F(StudioReference, ACancelledRenderStopsAndTheNextOneStarts) {
  RIGC_REQUIRE_TOOL(find_executable("povray"), "povray");
  ASSERT_EQ(start("povray", 1600)->status, 200);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  const auto began = std::chrono::steady_clock::now();
  ASSERT_EQ(client_->Post("/api/reference/cancel", "{}", "application/json")->status, 200);
  const nlohmann::json status = wait(30);
  EXPECT_EQ(status["state"], "cancelled") << status.dump(1);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count(), 10);
  EXPECT_EQ(client_->Get("/api/reference/image")->status, 404);
}

// A povray that fails (a wrapper in front of the real one): the page gets the message and the
// log's path.
TEST_F(StudioReference, AFailingRendererIsReportedWithItsLog) {
  RIGC_REQUIRE_TOOL(find_executable("povray"), "povray");
  fs::create_directories(dir_.path() / "bin");
  const fs::path wrapper = dir_.path() / "bin" / "povray";
  testing::write_text(wrapper.string(), "#!/bin/sh\necho 'Parse Error: broken' >&2\nexit 7\n");
  fs::permissions(wrapper, fs::perms::owner_all);
  const std::string path = std::getenv("PATH");
  setenv("PATH", ((dir_.path() / "bin").string() + ":" + path).c_str(), 1);
  const auto res = start("povray", 96);
  const nlohmann::json status = wait(60);
  setenv("PATH", path.c_str(), 1);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(status["state"], "failed") << status.dump(1);
  const std::string message = status["message"];
  EXPECT_THAT(message, HasSubstr("failed with exit code 7"));
  const std::string log = status["log"];
  EXPECT_THAT(message, HasSubstr(log));
  EXPECT_TRUE(fs::exists(log));
  EXPECT_EQ(start("nonesuch", 96)->status, 422);
  EXPECT_EQ(start("preview", 96)->status, 422);
  EXPECT_EQ(start("povray", 5)->status, 422);
}

TEST(StudioReferenceProgress, ReadsPovrayAndBlenderLogs) {
  EXPECT_LT(render_progress_from_log("Parsing...\n"), 0);
  EXPECT_DOUBLE_EQ(render_progress_from_log("Rendered 10 of 40 pixels\nRendered 20 of 40 pixels"),
                   0.5);
  EXPECT_DOUBLE_EQ(render_progress_from_log("Fra:1 Mem:10M | Sample 16/64\n"), 0.25);
}

}  // namespace
}  // namespace rigc::studio
