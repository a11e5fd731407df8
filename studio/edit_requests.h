// The studio's edit requests apart from HTTP: each POST route's body read and checked, then the
// session's change. The server answers its edit routes with these, and the fuzz harness
// (fuzz/entries.h, studio_edits) calls them directly.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "studio/session.h"

namespace rigc::studio {

// An answer: its HTTP status and JSON body ({"ok": true, ...} or {"error": "..."}).
struct EditAnswer {
  int status = 200;
  nlohmann::json body;
};

// The edit routes, each answered by answer_edit: /api/set, /api/view, /api/lights/add,
// /api/lights/remove, /api/suggest, /api/reference, /api/capture, /api/undo, /api/save.
std::span<const std::string_view> edit_routes();

// The answer to POST `route` with `body`: 400 for a body that is not what the route takes (not
// a JSON object, nested deeper than 16 levels, a key or value of the wrong form), 422 for a
// change the scene refuses, 404 for a route that is no edit route.
EditAnswer answer_edit(Session& session, std::string_view route, const std::string& body);

// The JSON text an answer is sent as: bytes that are not UTF-8 (a scene's broken line quoted in
// its diagnostics) become U+FFFD instead of an exception and a 500 for every answer.
std::string answer_text(const nlohmann::json& body);

// `body` as a JSON object nested at most 16 levels deep, or nullopt and why in `answer`.
std::optional<nlohmann::json> json_object_body(const std::string& body, EditAnswer* answer);

}  // namespace rigc::studio
