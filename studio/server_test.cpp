// The studio's HTTP API, through a real server on an ephemeral port and httplib's client.
#include "studio/server.h"

#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <numeric>
#include <sstream>
#include <thread>

#include "analysis/coverage.h"
#include "compiler/frontend.h"
#include "studio/server_test_support.h"
#include "tests/test_support.h"

namespace rigc::studio {
namespace {

using ::testing::HasSubstr;

std::string read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class StudioApi : public StudioServerTest {
 protected:
  nlohmann::json state() {
    const auto res = client_->Get("/api/state");
    EXPECT_TRUE(res && res->status == 200);
    return nlohmann::json::parse(res->body);
  }
  httplib::Result post(const std::string& path, const nlohmann::json& body) {
    return client_->Post(path.c_str(), body.dump(), "application/json");
  }
  double frame_mean(int width = 320) {
    const auto res = client_->Get(("/api/frame?width=" + std::to_string(width)).c_str());
    EXPECT_TRUE(res && res->status == 200);
    return std::stod(res->get_header_value("X-Rigc-Mean"));
  }
};

// A draft (the frames while something moves) point-samples the surface: the same view, about
// the same brightness, not the same pixels.
TEST_F(StudioApi, DraftFrameIsTheViewPointSampled) {
  const auto full = client_->Get("/api/frame?width=480");
  const auto draft = client_->Get("/api/frame?width=480&draft=1");
  ASSERT_TRUE(full && draft);
  ASSERT_EQ(full->status, 200) << full->body;
  ASSERT_EQ(draft->status, 200) << draft->body;
  EXPECT_EQ(draft->get_header_value("X-Rigc-Reused-Render"), "0");
  EXPECT_NE(full->body, draft->body);
  const double full_mean = std::stod(full->get_header_value("X-Rigc-Mean"));
  EXPECT_NEAR(std::stod(draft->get_header_value("X-Rigc-Mean")), full_mean, 0.05 * full_mean);
}

// The answers go uncompressed whatever the browser accepts: a coverage's megabyte of JSON took a
// second to compress with Brotli, for a loopback that gains nothing from it.
TEST_F(StudioApi, AnswersAreNotCompressed) {
  const httplib::Headers browser = {{"Accept-Encoding", "gzip, deflate, br"}};
  for (const char* path : {"/api/mesh", "/api/coverage", "/panels.js"}) {
    const auto res = client_->Get(path, browser);
    ASSERT_TRUE(res);
    ASSERT_EQ(res->status, 200) << path << ": " << res->body;
    EXPECT_EQ(res->get_header_value("Content-Encoding"), "") << path;
    EXPECT_GT(res->body.size(), 1000u) << path;
  }
  EXPECT_TRUE(nlohmann::json::accept(client_->Get("/api/mesh", browser)->body));
}

// The page's import map names each module with the token; every one it names is served, and the
// state carries the camera tables the sliders step through.
TEST_F(StudioApi, EveryModuleThePageImportsIsServed) {
  const auto page = client_->Get("/");
  ASSERT_TRUE(page);
  ASSERT_EQ(page->status, 200);
  std::vector<std::string> modules;
  for (std::size_t at = 0; (at = page->body.find("\"./", at)) != std::string::npos; ++at) {
    const std::size_t end = page->body.find("?token=", at);
    if (end != std::string::npos && page->body.compare(end - 3, 3, ".js") == 0) {
      modules.push_back(page->body.substr(at + 2, end - at - 2));
    }
  }
  EXPECT_GE(modules.size(), 8u);
  for (const std::string& module : modules) {
    const auto res = client_->Get(module);
    ASSERT_TRUE(res) << module;
    EXPECT_EQ(res->status, 200) << module;
    EXPECT_THAT(res->get_header_value("Content-Type"), HasSubstr("javascript")) << module;
  }
  const nlohmann::json state = nlohmann::json::parse(client_->Get("/api/state")->body);
  EXPECT_EQ(state["stops"]["apertures"].front(), 1.2);
  EXPECT_EQ(state["stops"]["shutters"].back(), 1.0 / 8000);
  EXPECT_EQ(state["stops"]["isos"].size(), 24u);
}

TEST_F(StudioApi, FrameIsAJpegOfTheRequestedWidthWithItsHistogram) {
  const auto res = client_->Get("/api/frame?width=320");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(res->get_header_value("Content-Type"), "image/jpeg");
  ASSERT_GT(res->body.size(), 1000u);
  EXPECT_EQ(static_cast<unsigned char>(res->body[0]), 0xFF);
  EXPECT_EQ(static_cast<unsigned char>(res->body[1]), 0xD8);
  std::vector<long> bins;
  std::stringstream parts(res->get_header_value("X-Rigc-Histogram"));
  for (std::string part; std::getline(parts, part, ',');) bins.push_back(std::stol(part));
  ASSERT_EQ(bins.size(), 256u);
  const long pixels = std::accumulate(bins.begin() + 192, bins.end(), 0L);
  EXPECT_EQ(pixels, 320L * 213);  // the canon-6d's 3:2 sensor at 320 px across
  EXPECT_GT(std::stod(res->get_header_value("X-Rigc-Mean")), 5);
}

TEST_F(StudioApi, ALongerShutterBrightensTheFrameAndChangesTheState) {
  const double before = frame_mean();
  const auto res = post("/api/set", {{"path", "camera.exposure.shutter"}, {"value", "1/30"}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_NEAR(state()["camera"]["shutter_s"].get<double>(), 1.0 / 30, 1e-9);
  EXPECT_TRUE(state()["unsaved"].get<bool>());
  EXPECT_GT(frame_mean(), before * 1.3);
}

TEST_F(StudioApi, ALensPresetIsSetWithAFocalLengthItTakesAndRefusedOtherwise) {
  const nlohmann::json lenses = state()["lenses"];
  ASSERT_GE(lenses.size(), 6u);
  EXPECT_EQ(state()["lens"], "");
  const auto zoom = post(
      "/api/set", {{"changes",
                    {{{"path", "camera.lens.preset"}, {"value", "canon-ef-24-70mm-f2.8l-ii-usm"}},
                     {{"path", "camera.lens.focal_length"}, {"value", "35mm"}}}}});
  ASSERT_TRUE(zoom);
  ASSERT_EQ(zoom->status, 200) << zoom->body;
  EXPECT_EQ(state()["lens"], "canon-ef-24-70mm-f2.8l-ii-usm");
  EXPECT_NEAR(state()["camera"]["focal_length_mm"].get<double>(), 35, 1e-9);
  // 85 mm is beyond the zoom: refused at the line, and the last good scene stays.
  const auto outside = post("/api/set", {{"path", "camera.lens.focal_length"}, {"value", "85mm"}});
  ASSERT_TRUE(outside);
  EXPECT_EQ(outside->status, 422);
  const std::string message = nlohmann::json::parse(outside->body)["error"];
  EXPECT_THAT(message, HasSubstr("scene.yaml:18:24:"));
  EXPECT_THAT(message, HasSubstr("is outside the lens canon-ef-24-70mm-f2.8l-ii-usm's 24mm-70mm"));
  EXPECT_NEAR(state()["camera"]["focal_length_mm"].get<double>(), 35, 1e-9);
}

TEST_F(StudioApi, AnOutOfRangeValueIsRefusedWithTheCompilersMessage) {
  const auto res = post("/api/set", {{"path", "camera.exposure.aperture"}, {"value", "f/0.8"}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 422);
  const std::string message = nlohmann::json::parse(res->body)["error"];
  EXPECT_THAT(message, HasSubstr("scene.yaml:"));
  EXPECT_THAT(message, HasSubstr("error: aperture f/0.8 is outside"));
  EXPECT_THAT(message, HasSubstr("aperture: f/0.8")) << "the source line: " << message;
  EXPECT_DOUBLE_EQ(state()["camera"]["aperture"].get<double>(), 11);  // the last good scene
}

TEST_F(StudioApi, ACameraBelowTheFloorOrInTheTableIsRefused) {
  auto res = post("/api/view", {{"position", {0.5, -0.5, -0.2}}, {"look_at", {0, 0, 0.8}}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 422);
  EXPECT_THAT(res->body, HasSubstr("below the floor"));
  res = post("/api/view", {{"position", {0.05, 0, 0.74}}, {"look_at", {0, 0, 0.9}}});
  EXPECT_EQ(res->status, 422);
  EXPECT_THAT(res->body, HasSubstr("inside the turntable"));
  res = post("/api/view",
             {{"position", {0.6, -0.6, 1.1}}, {"look_at", {0, 0, 0.85}}, {"turntable_deg", 30}});
  EXPECT_EQ(res->status, 200) << res->body;
  EXPECT_NEAR(state()["view"]["turntable_deg"].get<double>(), 30, 1e-9);
}

TEST_F(StudioApi, CaptureAddsAShotToTheCoverageAndUndoTakesItBack) {
  const int shots = state()["shots"];
  auto coverage = nlohmann::json::parse(client_->Get("/api/coverage")->body);
  EXPECT_EQ(coverage["shots"].get<int>(), shots);
  const double seen_before = coverage["seen_1"];
  ASSERT_EQ(post("/api/view", {{"position", {0, -0.8, 1.0}}, {"look_at", {0, 0, 0.85}}})->status,
            200);
  ASSERT_EQ(post("/api/capture", {})->status, 200);
  EXPECT_EQ(state()["shots"].get<int>(), shots + 1);
  coverage = nlohmann::json::parse(client_->Get("/api/coverage")->body);
  EXPECT_EQ(coverage["shots"].get<int>(), shots + 1);
  EXPECT_GT(coverage["seen_1"].get<double>(), seen_before + 0.1);
  EXPECT_THAT(coverage["table"].get<std::string>(), HasSubstr("shot_001"));
  ASSERT_EQ(post("/api/undo", {})->status, 200);
  EXPECT_EQ(state()["shots"].get<int>(), shots);
  EXPECT_EQ(post("/api/undo", {})->status, 422);  // nothing left to undo
}

// Captures and their undo reuse the analysis of the shots before; a camera change starts it
// again. Either way the page gets what `rigc coverage` computes for the scene as saved.
TEST_F(StudioApi, CapturesUndoAndChangesGiveTheCoverageOfAFullAnalysis) {
  const auto expect_full_coverage = [&](const char* after) {
    const auto res = client_->Get("/api/coverage");
    ASSERT_TRUE(res && res->status == 200) << after;
    const auto coverage = nlohmann::json::parse(res->body);
    ASSERT_EQ(post("/api/save", {})->status, 200) << after;
    DiagnosticEngine diag;
    rigc::testing::silence_diagnostics(diag);
    const auto scene = compile_scene_file(scene_file_.string(), diag);
    ASSERT_TRUE(scene) << after;
    const auto full = analysis::analyse_coverage(*scene, scene::prepare_studio_scene(*scene));
    EXPECT_EQ(coverage["views"].get<std::vector<int>>(),
              std::vector<int>(full.views.begin(), full.views.end()))
        << after;
    EXPECT_NEAR(coverage["reconstructable"].get<double>(), full.shots.back().reconstructable, 1e-9)
        << after;
    EXPECT_NEAR(coverage["seen_2"].get<double>(), full.shots.back().seen_2, 1e-9) << after;
    EXPECT_EQ(coverage["shots"].get<size_t>(), full.shots.size()) << after;
  };
  const auto capture_from = [&](double x, double y) {
    ASSERT_EQ(post("/api/view", {{"position", {x, y, 1.0}}, {"look_at", {0, 0, 0.85}}})->status,
              200);
    ASSERT_EQ(post("/api/capture", {})->status, 200);
  };
  expect_full_coverage("at the start");
  capture_from(0, -0.8);
  capture_from(-0.6, -0.5);
  expect_full_coverage("after two captures");
  ASSERT_EQ(post("/api/undo", {})->status, 200);
  capture_from(-0.7, 0.3);
  expect_full_coverage("after an undo and a capture");
  ASSERT_EQ(post("/api/set", {{"path", "camera.exposure.aperture"}, {"value", "f/4"}})->status,
            200);
  expect_full_coverage("after a change of the aperture");
}

// The renderer's frame is kept while only what the DSLR model applies changes.
TEST_F(StudioApi, AnExposureChangeReusesTheRenderedFrame) {
  const auto get = [&] {
    const auto res = client_->Get("/api/frame?width=320");
    EXPECT_TRUE(res && res->status == 200);
    return std::make_pair(res->get_header_value("X-Rigc-Reused-Render") == "1",
                          std::stod(res->get_header_value("X-Rigc-Mean")));
  };
  const auto first = get();
  EXPECT_FALSE(first.first);
  ASSERT_EQ(post("/api/set", {{"path", "camera.exposure.iso"}, {"value", "400"}})->status, 200);
  const auto brighter = get();
  EXPECT_TRUE(brighter.first);
  EXPECT_GT(brighter.second, first.second * 1.2);
  ASSERT_EQ(post("/api/view", {{"position", {0.7, -0.4, 1.0}}, {"look_at", {0, 0, 0.85}}})->status,
            200);
  EXPECT_FALSE(get().first);
  ASSERT_EQ(post("/api/set", {{"path", "studio.ambient"}, {"value", "200lx"}})->status, 200);
  EXPECT_FALSE(get().first);  // the studio changed: rendered again
}

TEST_F(StudioApi, SuggestMovesTheViewToThePlannersNextShot) {
  const auto view_before = state()["view"];
  const auto res = post("/api/suggest", {});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const auto suggestion = nlohmann::json::parse(res->body);
  EXPECT_GT(suggestion["gain"].get<double>(), 0.05);
  EXPECT_THAT(suggestion["entry"].get<std::string>(),
              HasSubstr("# Suggested by `rigc plan --next`"));
  EXPECT_NE(state()["view"], view_before);
  // Captured, the suggestion brings the coverage the planner promised.
  ASSERT_EQ(post("/api/capture", {})->status, 200);
  const auto coverage = nlohmann::json::parse(client_->Get("/api/coverage")->body);
  EXPECT_EQ(coverage["shots"].get<int>(), 2);
  EXPECT_NEAR(coverage["reconstructable"].get<double>(),
              suggestion["reconstructable"].get<double>(), 0.01);
}

TEST_F(StudioApi, SaveWritesTheEditsAndCapturesAndKeepsTheComments) {
  ASSERT_EQ(post("/api/set", {{"path", "camera.exposure.aperture"}, {"value", "f/8"}})->status,
            200);
  ASSERT_EQ(post("/api/capture", {})->status, 200);
  EXPECT_EQ(read(scene_file_), kStudioTestScene);  // nothing written before the save
  ASSERT_EQ(post("/api/save", {})->status, 200);
  const std::string saved = read(scene_file_);
  EXPECT_THAT(saved, HasSubstr("# The studio's test scene"));
  EXPECT_THAT(saved, HasSubstr("    # the key light, left of the camera\n"));
  EXPECT_THAT(saved, HasSubstr("exposure: {aperture: f/8, shutter: 1/125, iso: 200}  # daylight"));
  EXPECT_THAT(saved, HasSubstr("\n  - pose: {position: ["));
  DiagnosticEngine diag;
  rigc::testing::silence_diagnostics(diag);
  const auto scene = compile_scene_file(scene_file_.string(), diag);
  ASSERT_TRUE(scene);
  EXPECT_EQ(scene->shots.size(), 2u);
  EXPECT_DOUBLE_EQ(scene->camera.aperture_f_number, 8);
  EXPECT_FALSE(state()["unsaved"].get<bool>());
}

TEST_F(StudioApi, ReloadsTheFileAndShowsItsErrorsKeepingTheLastGoodScene) {
  std::string text = kStudioTestScene;
  text.replace(text.find("iso: 200"), 8, "iso: 400");
  std::ofstream(scene_file_) << text;
  EXPECT_DOUBLE_EQ(state()["camera"]["iso"].get<double>(), 400);
  text.replace(text.find("iso: 400"), 8, "iso: -3");
  std::ofstream(scene_file_) << text;
  const nlohmann::json broken = state();
  const std::string error = broken["file_error"];
  EXPECT_THAT(error, HasSubstr("scene.yaml:"));
  EXPECT_THAT(error, HasSubstr(": error: "));
  EXPECT_THAT(error, HasSubstr("iso: -3")) << "the source line: " << error;
  EXPECT_DOUBLE_EQ(broken["camera"]["iso"].get<double>(), 400);
  EXPECT_EQ(client_->Get("/api/frame?width=200")->status, 200);
}

TEST_F(StudioApi, BadRequestsGetA4xxAndTheServerStaysUp) {
  httplib::Client bare("127.0.0.1", server_->port());
  EXPECT_EQ(bare.Get("/api/state")->status, 403);
  EXPECT_EQ(bare.Get("/?token=0123")->status, 403);
  EXPECT_EQ(bare.Get(("/?token=" + server_->token()).c_str())->status, 200);
  const std::string port = std::to_string(server_->port());
  EXPECT_EQ(client_->Get("/api/state", {{"Host", "evil.example:" + port}})->status, 403);
  EXPECT_EQ(client_->Get("/api/state", {{"Origin", "http://evil.example"}})->status, 403);
  EXPECT_EQ(client_->Get("/api/state", {{"Origin", "http://localhost:" + port}})->status, 200);
  EXPECT_EQ(client_->Post("/api/set", "{not json", "application/json")->status, 400);
  EXPECT_EQ(client_->Post("/api/set", "[1, 2]", "application/json")->status, 400);
  EXPECT_EQ(post("/api/set", {{"path", "object.mesh"}, {"value", "/etc/passwd"}})->status, 422);
  EXPECT_EQ(post("/api/set", {{"path", "camera.body"}, {"value", "x}\nobject: {"}})->status, 422);
  EXPECT_EQ(post("/api/view", {{"position", "up"}})->status, 400);
  EXPECT_EQ(post("/api/lights/remove", {{"index", 99}})->status, 422);
  EXPECT_EQ(post("/api/lights/add", {{"type", "point"}, {"position: [1", "2]"}})->status, 400);
  EXPECT_EQ(client_->Get("/api/frame?width=5")->status, 400);
  EXPECT_EQ(client_->Get("/api/frame?width=200&draft=yes")->status, 400);
  EXPECT_EQ(client_->Get("/api/nothing")->status, 404);
  EXPECT_EQ(client_->Get("/api/state")->status, 200);
}

// A body nested far deeper than any request is refused while it is parsed: copying such a value
// recursed until the stack overflowed, and the unsaved edits went with the process.
TEST_F(StudioApi, ADeeplyNestedBodyIsRefusedAndTheServerStaysUp) {
  const std::string deep = std::string(60000, '[') + std::string(60000, ']');
  for (const char* route : {"/api/set", "/api/view", "/api/reference", "/api/lights/add"}) {
    const auto res = client_->Post(route, "{\"path\": " + deep + "}", "application/json");
    ASSERT_TRUE(res) << route;
    EXPECT_EQ(res->status, 400) << route;
    EXPECT_THAT(res->body, HasSubstr("nests deeper than")) << route;
  }
  EXPECT_EQ(client_->Get("/api/state")->status, 200);
}

// Keys are checked like values: a key with a newline or YAML's punctuation would write a section
// of its own into the scene.
TEST_F(StudioApi, APathKeyThatIsNotASceneKeyIsRefused) {
  for (const char* path : {"camera.body\ncoverage", "camera.exposure.iso: 3\ncoverage",
                           "studio.{lights}", "camera..iso", "camera.Exposure"}) {
    const auto res = post("/api/set", {{"path", path}, {"value", "400"}});
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 422) << path;
    EXPECT_THAT(res->body, HasSubstr("is not a scene key")) << path;
  }
  EXPECT_FALSE(state()["unsaved"].get<bool>());
}

// Save replaces the file the studio opened and read, and nothing else: not a file a symbolic link
// put in its place leads to, nor edits made on disk since the last read.
TEST_F(StudioApi, SaveRefusesALinkPutInTheScenesPlaceAndEditsMadeOnDisk) {
  const std::filesystem::path elsewhere = dir_.path() / "elsewhere.txt";
  std::ofstream(elsewhere) << "not a scene\n";
  ASSERT_EQ(post("/api/set", {{"path", "camera.exposure.iso"}, {"value", "400"}})->status, 200);
  std::filesystem::remove(scene_file_);
  std::filesystem::create_symlink(elsewhere, scene_file_);
  auto res = post("/api/save", {});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 422);
  EXPECT_THAT(res->body, HasSubstr("not to the file the studio opened"));
  EXPECT_EQ(read(elsewhere), "not a scene\n");

  std::filesystem::remove(scene_file_);
  std::string edited = kStudioTestScene;
  edited.replace(edited.find("iso: 200"), 8, "iso: 800");
  std::ofstream(scene_file_) << edited;  // between two polls of the page
  res = post("/api/save", {});
  EXPECT_EQ(res->status, 422);
  EXPECT_THAT(res->body, HasSubstr("changed on disk since the studio read it (line"));
  EXPECT_THAT(res->body, HasSubstr("iso: 800"));
  EXPECT_EQ(read(scene_file_), edited);
  // Once the studio has read it (the page's next poll), Save writes the studio's scene.
  EXPECT_DOUBLE_EQ(state()["camera"]["iso"].get<double>(), 800);
  ASSERT_EQ(post("/api/set", {{"path", "camera.exposure.iso"}, {"value", "400"}})->status, 200);
  EXPECT_EQ(post("/api/save", {})->status, 200);
  EXPECT_THAT(read(scene_file_), HasSubstr("iso: 400"));
}

// A pipe, a folder or a file past the scene limit in the scene's place is named in the state,
// at once: the studio neither waits on the pipe nor reads the file, and keeps the last good scene.
TEST_F(StudioApi, APipeAFolderOrAHugeFileInTheScenesPlaceIsNamedAndTheSceneKept) {
  std::filesystem::remove(scene_file_);
  ASSERT_EQ(::mkfifo(scene_file_.c_str(), 0600), 0);
  nlohmann::json s = state();
  EXPECT_THAT(s["file_error"].get<std::string>(), HasSubstr("is not a regular file"));
  EXPECT_EQ(s["name"], "studio-test");
  EXPECT_EQ(post("/api/save", {})->status, 422);
  std::filesystem::remove(scene_file_);
  std::filesystem::create_directory(scene_file_);
  EXPECT_THAT(state()["file_error"].get<std::string>(), HasSubstr("is a folder"));
  std::filesystem::remove(scene_file_);
  std::ofstream(scene_file_) << kStudioTestScene << std::string(17 << 20, '#');
  EXPECT_THAT(state()["file_error"].get<std::string>(), HasSubstr("is larger than 16 MB"));
  std::ofstream(scene_file_) << kStudioTestScene;
  EXPECT_EQ(state()["file_error"], "");
  EXPECT_EQ(client_->Get("/api/frame?width=200")->status, 200);
}

// A byte that is not UTF-8 in the scene on disk is the file's error, located, and every answer
// stays JSON (it made each /api/state a 500).
TEST_F(StudioApi, ASceneWithABrokenByteIsAFileErrorAndTheStateStaysJson) {
  std::string text = kStudioTestScene;
  text.replace(text.find("name: studio-test"), 17, "name: caf\xe9");
  std::ofstream(scene_file_) << text;
  const auto res = client_->Get("/api/state");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  const auto s = nlohmann::json::parse(res->body);
  EXPECT_THAT(s["file_error"].get<std::string>(), HasSubstr("not valid UTF-8"));
  EXPECT_EQ(s["name"], "studio-test");
}

// Listening on every interface, the server answers to the machine's own names and addresses.
class StudioOnEveryInterface : public StudioServerTest {
 protected:
  ServerOptions server_options() const override {
    ServerOptions options;
    options.host = "0.0.0.0";
    return options;
  }
};

TEST_F(StudioOnEveryInterface, TheMachinesOwnNamesAreAccepted) {
  char hostname[256] = {};
  gethostname(hostname, sizeof hostname - 1);
  const std::string suffix = ":" + std::to_string(server_->port());
  for (const std::string& name : std::vector<std::string>{"127.0.0.1", "localhost", hostname}) {
    EXPECT_EQ(client_->Get("/api/state", {{"Host", name + suffix}})->status, 200) << name;
  }
  EXPECT_EQ(client_->Get("/api/state", {{"Host", "evil.example" + suffix}})->status, 403);
  EXPECT_EQ(client_->Get("/api/state", {{"Host", "0.0.0.0" + suffix}})->status, 403);
}

// Connects to 127.0.0.1:port; -1 when it cannot.
int connect_to(int port) {
  const int sock = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(sock, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(sock);
    return -1;
  }
  return sock;
}

// A short deadline and fewer workers than slow clients.
class StudioWithADeadline : public StudioServerTest {
 protected:
  ServerOptions server_options() const override {
    ServerOptions options;
    options.request_deadline = std::chrono::milliseconds(500);
    options.workers = 4;
    return options;
  }
};

// Slow clients, more than there are workers, each sending its request's header a byte at a
// time: the server closes each when its request is late, and answers a quick client meanwhile.
TEST_F(StudioWithADeadline, ClientsTricklingTheirHeadersAreClosedAndOthersServed) {
  const int port = server_->port();
  const std::string request = "GET /api/state HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                              "\r\nX-Rigc-Token: " + server_->token() + "\r\n\r\n";
  constexpr int kSlowClients = 8;  // twice the workers
  std::vector<std::size_t> sent(kSlowClients, 0);
  std::vector<std::thread> slow;
  for (int c = 0; c < kSlowClients; ++c) {
    slow.emplace_back([&, c] {
      const int sock = connect_to(port);
      if (sock < 0) return;
      // One byte every 100 ms: the whole header would take over 10 s.
      for (; sent[c] < request.size(); ++sent[c]) {
        if (::send(sock, &request[sent[c]], 1, MSG_NOSIGNAL) != 1) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        char byte;
        if (::recv(sock, &byte, 1, MSG_DONTWAIT) == 0) break;  // closed by the server
      }
      ::close(sock);
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto res = client_->Get("/api/state");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  for (auto& t : slow) t.join();
  for (int c = 0; c < kSlowClients; ++c) {
    EXPECT_LT(sent[c], request.size()) << "slow client " << c << " sent its whole request";
  }
}

TEST_F(StudioApi, LightsAreAddedChangedAndRemoved) {
  const size_t lights = state()["studio"]["lights"].size();
  ASSERT_EQ(post("/api/lights/add",
                 {{"type", "point"}, {"position", "[1m, -1m, 1.5m]"}, {"power", "150W"}})
                ->status,
            200);
  EXPECT_EQ(state()["studio"]["lights"].size(), lights + 1);
  ASSERT_EQ(post("/api/set", {{"path", "studio.lights." + std::to_string(lights) + ".power"},
                              {"value", "250W"}})
                ->status,
            200);
  EXPECT_DOUBLE_EQ(state()["studio"]["lights"][lights]["power_w"].get<double>(), 250);
  ASSERT_EQ(post("/api/lights/remove", {{"index", 0}})->status, 200);
  EXPECT_EQ(state()["studio"]["lights"].size(), lights);
  ASSERT_EQ(
      post("/api/set", {{"path", "studio.backdrop.green_screen"}, {"value", "false"}})->status,
      200);
  EXPECT_FALSE(state()["studio"]["green_screen"].get<bool>());
}

TEST_F(StudioApi, AdviceComesAtTheScenesLines) {
  ASSERT_EQ(post("/api/set", {{"path", "camera.exposure.shutter"}, {"value", "2s"}})->status, 200);
  const auto advice = nlohmann::json::parse(client_->Get("/api/advice")->body);
  ASSERT_TRUE(advice.is_array());
  bool exposure_line = false;
  for (const auto& d : advice) {
    exposure_line = exposure_line || d["line"].get<int>() == kStudioTestSceneExposureLine;
  }
  EXPECT_TRUE(exposure_line) << advice.dump(1);
}

// Advice given for a scene is given again when the scene comes back, and only then: a setting
// turned away and back brings its warnings and takes them away again.
TEST_F(StudioApi, AdviceFollowsASettingTurnedBackAndForth) {
  const auto advice_text = [&] {
    std::string messages;
    for (const auto& d : nlohmann::json::parse(client_->Get("/api/advice")->body)) {
      messages += d["message"].get<std::string>() + "\n";
    }
    return messages;
  };
  const std::string shutter = state()["camera"]["shutter_s"].dump() + "s";
  const std::string before = advice_text();
  ASSERT_EQ(post("/api/set", {{"path", "camera.exposure.shutter"}, {"value", "2s"}})->status, 200);
  const std::string slow = advice_text();
  EXPECT_NE(slow, before);
  for (int round = 0; round < 2; ++round) {
    ASSERT_EQ(post("/api/set", {{"path", "camera.exposure.shutter"}, {"value", shutter}})->status,
              200);
    EXPECT_EQ(advice_text(), before) << "round " << round;
    ASSERT_EQ(post("/api/set", {{"path", "camera.exposure.shutter"}, {"value", "2s"}})->status,
              200);
    EXPECT_EQ(advice_text(), slow) << "round " << round;
  }
}

}  // namespace
}  // namespace rigc::studio
