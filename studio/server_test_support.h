// A studio on the test scene, served on an ephemeral port, with an httplib client that carries
// its token: the fixture of the studio's API tests.
#pragma once

#include <gtest/gtest.h>
#include <httplib.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>

#include "studio/scene_test_support.h"
#include "studio/server.h"
#include "studio/session.h"
#include "tests/test_support.h"

namespace rigc::studio {

class StudioServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_file_ = dir_.path() / "scene.yaml";
    std::ofstream(scene_file_) << kStudioTestScene;
    std::string error;
    session_ = Session::open(scene_file_, &error, dir_.path() / "run");
    ASSERT_TRUE(session_) << error;
    server_ = std::make_unique<StudioServer>(*session_, server_options());
    const int port = server_->bind(&error);
    ASSERT_GT(port, 0) << error;
    thread_ = std::thread([this] { server_->run(); });
    while (!server_->is_running()) std::this_thread::yield();
    client_ = std::make_unique<httplib::Client>("127.0.0.1", port);
    client_->set_read_timeout(60);
    client_->set_default_headers({{"X-Rigc-Token", server_->token()}});
  }
  // The server's options: a test fixture of its own overrides them.
  virtual ServerOptions server_options() const { return {}; }

  void TearDown() override {
    if (server_) server_->stop();
    if (thread_.joinable()) thread_.join();
  }

  testing::TempDir dir_;
  std::filesystem::path scene_file_;
  std::unique_ptr<Session> session_;
  std::unique_ptr<StudioServer> server_;
  std::thread thread_;
  std::unique_ptr<httplib::Client> client_;
};

}  // namespace rigc::studio
