#include "studio/edit_requests.h"

#include <fmt/format.h>

#include <array>
#include <numbers>
#include <sstream>
#include <utility>
#include <vector>

#include "compiler/scene_text.h"

namespace rigc::studio {

using nlohmann::json;

namespace {

EditAnswer refused(int status, const std::string& message) {
  return {status, json{{"error", message}}};
}

EditAnswer outcome_answer(const Outcome& outcome) {
  return outcome.ok ? EditAnswer{200, json{{"ok", true}}} : refused(422, outcome.message);
}

std::optional<Eigen::Vector3d> vec3(const json& value) {
  if (!value.is_array() || value.size() != 3) return std::nullopt;
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    if (!value[i].is_number()) return std::nullopt;
    v[i] = value[i].get<double>();
  }
  return v;
}

// {"path": "camera.lens.focal_length", "value": "35mm"}, or {"changes": [such, ...]} for several
// values in one change.
EditAnswer set_values(Session& session, const json& body) {
  const json changes = body.contains("changes") ? body["changes"] : json::array({body});
  std::vector<std::pair<ScenePath, std::string>> values;
  for (const auto& change : changes) {
    if (!change.is_object() || !change.contains("path") || !change["path"].is_string() ||
        !change.contains("value") || !change["value"].is_string() || changes.size() > 8) {
      return refused(400,
                     "set takes {\"path\": \"camera.lens.focal_length\", \"value\": \"35mm\"} or "
                     "{\"changes\": [such, ...]} (at most 8)");
    }
    ScenePath path;
    std::stringstream parts(change["path"].get<std::string>());
    for (std::string part; std::getline(parts, part, '.');) path.push_back(part);
    values.emplace_back(std::move(path), change["value"].get<std::string>());
  }
  if (values.empty()) return refused(400, "set takes at least one change");
  return outcome_answer(session.set_values(values));
}

EditAnswer set_view(Session& session, const json& body) {
  const auto position = vec3(body.value("position", json()));
  const auto look_at = vec3(body.value("look_at", json()));
  const json angle = body.value("turntable_deg", json(0.0));
  if (!position || !look_at || !angle.is_number()) {
    return refused(400, "view takes position and look_at ([x, y, z] in metres) and turntable_deg");
  }
  return outcome_answer(
      session.set_view({*position, *look_at, angle.get<double>() * std::numbers::pi / 180}));
}

EditAnswer add_light(Session& session, const json& body) {
  std::string entry;
  for (const auto& [key, value] : body.items()) {
    const bool word =
        !key.empty() && key.find_first_not_of("abcdefghijklmnopqrstuvwxyz_") == std::string::npos;
    if (!word || !value.is_string() || !is_safe_value_text(value.get<std::string>())) {
      return refused(400, "a light is a map of scene-language values");
    }
    entry += (entry.empty() ? "" : ", ") + key + ": " + value.get<std::string>();
  }
  return outcome_answer(session.add_light("{" + entry + "}"));
}

EditAnswer remove_light(Session& session, const json& body) {
  if (!body.contains("index") || !body["index"].is_number_unsigned()) {
    return refused(400, "remove takes {\"index\": N}");
  }
  return outcome_answer(session.remove_light(body["index"].get<size_t>()));
}

EditAnswer suggest(Session& session, const json&) {
  Suggestion suggestion;
  const Outcome outcome = session.suggest_next_shot(&suggestion);
  if (!outcome.ok) return refused(422, outcome.message);
  return {200, json{{"ok", true},
                    {"gain", suggestion.gain},
                    {"reconstructable", suggestion.reconstructable},
                    {"entry", suggestion.entry}}};
}

// The reference check of the current view: {backend, width, samples}.
EditAnswer start_reference(Session& session, const json& body) {
  ReferenceRequest request;
  const json backend = body.value("backend", json(request.backend));
  const json width = body.value("width", json(request.width));
  const json samples = body.value("samples", json(request.samples));
  if (!backend.is_string() || !width.is_number_integer() || !samples.is_number_integer()) {
    return refused(400,
                   "reference takes {\"backend\": \"povray\", \"width\": 640, \"samples\": 0}");
  }
  request.backend = backend.get<std::string>();
  request.width = width.get<int>();
  request.samples = samples.get<int>();
  return outcome_answer(session.start_reference(request));
}

struct Route {
  std::string_view path;
  EditAnswer (*answer)(Session&, const json&);
  bool takes_body;
};

constexpr std::array kRoutes = {
    Route{"/api/set", set_values, true},
    Route{"/api/view", set_view, true},
    Route{"/api/lights/add", add_light, true},
    Route{"/api/lights/remove", remove_light, true},
    Route{"/api/suggest", suggest, false},
    Route{"/api/reference", start_reference, true},
    Route{"/api/capture", [](Session& s, const json&) { return outcome_answer(s.capture()); },
          false},
    Route{"/api/undo", [](Session& s, const json&) { return outcome_answer(s.undo()); }, false},
    Route{"/api/save", [](Session& s, const json&) { return outcome_answer(s.save()); }, false},
};

constexpr auto kRoutePaths = [] {
  std::array<std::string_view, kRoutes.size()> paths{};
  for (std::size_t i = 0; i < kRoutes.size(); ++i) paths[i] = kRoutes[i].path;
  return paths;
}();

}  // namespace

std::string answer_text(const json& body) {
  return body.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::span<const std::string_view> edit_routes() {
  return kRoutePaths;
}

// The parser is iterative, but copying or destroying a value recurses: a body nested deeper than
// any request needs is refused while it is parsed, before a value of that depth exists.
std::optional<json> json_object_body(const std::string& body, EditAnswer* answer) {
  constexpr int kMostDepth = 16;
  bool too_deep = false;
  const json::parser_callback_t within_depth = [&too_deep](int depth, json::parse_event_t, json&) {
    too_deep = too_deep || depth > kMostDepth;
    return !too_deep;
  };
  json parsed = json::parse(body, within_depth, false);
  if (too_deep) {
    *answer =
        refused(400, fmt::format("the request's body nests deeper than {} levels", kMostDepth));
    return std::nullopt;
  }
  if (parsed.is_discarded() || !parsed.is_object()) {
    *answer = refused(400, "the request's body is not a JSON object");
    return std::nullopt;
  }
  return parsed;
}

EditAnswer answer_edit(Session& session, std::string_view route, const std::string& body) {
  for (const Route& r : kRoutes) {
    if (r.path != route) continue;
    if (!r.takes_body) return r.answer(session, json::object());
    EditAnswer answer;
    const auto parsed = json_object_body(body, &answer);
    return parsed ? r.answer(session, *parsed) : answer;
  }
  return refused(404, "no such request");
}

}  // namespace rigc::studio
