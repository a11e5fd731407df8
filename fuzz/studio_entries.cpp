// The studio's edit requests (studio/edit_requests.h) as the server answers them, without the
// sockets: a library of its own beside eval's, so that the other harnesses build without studio/.
#include <memory>
#include <stdexcept>
#include <string>

#include "fuzz/entries.h"
#include "fuzz/input_file.h"
#include "studio/edit_requests.h"
#include "studio/scene_test_support.h"

namespace rigc::fuzz {

namespace {

// One session on the studio's test scene, kept across inputs as a user's is (each edit starts
// from the last), and opened anew every 256 inputs so that its undo history stays bounded.
studio::Session& session() {
  static std::unique_ptr<studio::Session> open;
  static int uses = 0;
  if (!open || ++uses % 256 == 0) {
    open.reset();
    const auto scene = write_input(studio::kStudioTestScene, "studio_scene.yaml");
    std::string error;
    open = studio::Session::open(scene, &error, input_dir() / "studio_run");
    if (!open) throw std::logic_error("the studio's test scene does not open: " + error);
  }
  return *open;
}

}  // namespace

void studio_edits(std::string_view input) {
  // The first line names the route; the rest is the body. Unknown routes are answered 404 like
  // any; the reference check (renderers in the background) and the planner's suggestion (seconds
  // a call, no body) are left to the API tests.
  const std::size_t newline = input.find('\n');
  const std::string route(input.substr(0, newline));
  if (route == "/api/reference" || route == "/api/suggest") return;
  const std::string body(newline == std::string_view::npos ? "" : input.substr(newline + 1));
  const studio::EditAnswer answer = studio::answer_edit(session(), route, body);
  if (answer.status >= 500)
    throw std::logic_error("an edit request answered " + answer.body.dump());
  if (answer.status != 200 && !answer.body.contains("error")) {
    throw std::logic_error("a refused edit request says not why");
  }
  // Every answer is sent as JSON text: it must serialise.
  (void)studio::answer_text(answer.body);
}

}  // namespace rigc::fuzz
