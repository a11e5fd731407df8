// The limits table (compiler/limits.h) and the JSON Schema (schema/rigc.schema.json) state the
// same limits: every entry of the table is in the schema with the same bounds, and every bound in
// the schema is an entry of the table.
#include "compiler/limits.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "tests/test_support.h"

namespace rigc {
namespace {

using nlohmann::json;

// One bound keyword as the schema states it, at a value's path (the table's naming: keys from
// the top, lists, $refs and oneOf/allOf/if-then branches left out).
struct SchemaBound {
  std::string path;
  std::string keyword;  // minimum, maximum, exclusiveMinimum, exclusiveMaximum, const,
                        // maxLength, maxItems
  double value;
  std::set<std::string> defs;  // the $defs the value's schema refers to ("length", "angle", ...)
};

// Collects every bound of the schema. A list's fixed size (minItems == maxItems, as in
// [x, y, z]), non-emptiness (minItems, minLength) and fit's one key are its shape, not limits.
class BoundCollector {
 public:
  explicit BoundCollector(const json& schema) : schema_(schema) {}

  std::vector<SchemaBound> collect() {
    walk(schema_, "", {});
    // A bound in a $def that nothing refers to would hold no value: it is reported as such.
    for (const auto& [name, def] : schema_["$defs"].items()) {
      if (!reached_.count(name)) walk(def, "$defs." + name, {});
    }
    return bounds_;
  }

 private:
  void walk(const json& node, const std::string& path, std::set<std::string> defs) {
    if (!node.is_object()) return;
    if (node.contains("$ref")) {
      const std::string ref = node["$ref"];
      const std::string name = ref.substr(std::string("#/$defs/").size());
      reached_.insert(name);
      defs.insert(name);
      walk(schema_["$defs"][name], path, defs);
    }
    for (const char* keyword :
         {"minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "const", "maxLength"}) {
      if (node.contains(keyword) && node[keyword].is_number()) {
        bounds_.push_back({path, keyword, node[keyword].get<double>(), defs});
      }
    }
    if (node.contains("maxItems") && node.value("minItems", -1) != node["maxItems"]) {
      bounds_.push_back({path, "maxItems", node["maxItems"].get<double>(), defs});
    }
    if (node.contains("properties")) {
      for (const auto& [key, sub] : node["properties"].items()) {
        walk(sub, path.empty() ? key : path + "." + key, {});
      }
    }
    if (node.contains("items")) walk(node["items"], path, defs);
    for (const char* branches : {"oneOf", "anyOf", "allOf"}) {
      if (!node.contains(branches)) continue;
      for (const auto& sub : node[branches]) walk(sub, path, defs);
    }
    if (node.contains("then")) walk(node["then"], path, defs);
    if (node.contains("else")) walk(node["else"], path, defs);
  }

  const json& schema_;
  std::set<std::string> reached_;
  std::vector<SchemaBound> bounds_;
};

json load_schema() {
  std::ifstream in(testing::source_path("schema/rigc.schema.json"));
  return json::parse(in);
}

// The SI value of a bare number 1 of `kind`: the schema's bounds are bare numbers.
double si_per_bare_number(QuantityKind kind) {
  return *parse_quantity("1", kind).value;
}

// The $def that spells a quantity of `kind` in the schema.
std::string def_of(QuantityKind kind) {
  switch (kind) {
    case QuantityKind::kNumber:
      return "number";
    case QuantityKind::kLength:
      return "length";
    case QuantityKind::kAngle:
      return "angle";
    case QuantityKind::kTime:
      return "time";
    case QuantityKind::kFNumber:
      return "fnumber";
    case QuantityKind::kTemperature:
      return "temperature";
    case QuantityKind::kPower:
      return "power";
    case QuantityKind::kIlluminance:
      return "illuminance";
    case QuantityKind::kAngularVelocity:
      return "angular_velocity";
  }
  return "";
}

bool same(double a, double b) {
  return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b));
}

// What the table says a path's bound keywords must be, in the schema's terms.
std::map<std::string, double> expected_bounds(const limits::Quantity& limit) {
  const double unit = si_per_bare_number(limit.kind);
  return {{limit.min_exclusive ? "exclusiveMinimum" : "minimum", limit.min / unit},
          {"maximum", limit.max / unit}};
}
std::map<std::string, double> expected_bounds(const limits::Integer& limit) {
  if (limit.min == limit.max) return {{"const", limit.min}};
  return {{"minimum", limit.min}, {"maximum", limit.max}};
}
std::map<std::string, double> expected_bounds(const limits::Count& limit) {
  return {{limit.of == limits::Count::kBytes ? "maxLength" : "maxItems",
           static_cast<double>(limit.max)}};
}

// Every path of the table, with its bounds in the schema's terms.
std::map<std::string, std::map<std::string, double>> table_bounds() {
  std::map<std::string, std::map<std::string, double>> table;
  auto add = [&](std::string_view path, std::map<std::string, double> bounds) {
    EXPECT_TRUE(table.emplace(std::string(path), std::move(bounds)).second)
        << "two entries for " << path;
  };
  for (const auto& limit : limits::kQuantities) add(limit.path, expected_bounds(limit));
  for (const auto& limit : limits::kIntegers) add(limit.path, expected_bounds(limit));
  for (const auto& limit : limits::kCounts) add(limit.path, expected_bounds(limit));
  return table;
}

TEST(Limits, EveryEntryIsARange) {
  for (const auto& limit : limits::kQuantities) EXPECT_LT(limit.min, limit.max) << limit.path;
  for (const auto& limit : limits::kIntegers) EXPECT_LE(limit.min, limit.max) << limit.path;
  for (const auto& limit : limits::kCounts) EXPECT_GT(limit.max, 0u) << limit.path;
}

TEST(Limits, TheSchemaStatesEveryLimitOfTheTable) {
  const std::vector<SchemaBound> schema = BoundCollector(load_schema()).collect();
  for (const auto& [path, bounds] : table_bounds()) {
    for (const auto& [keyword, value] : bounds) {
      bool found = false;
      for (const auto& bound : schema) found |= bound.path == path && bound.keyword == keyword;
      EXPECT_TRUE(found) << "the schema lacks " << path << " " << keyword << " " << value;
    }
  }
}

TEST(Limits, EveryBoundInTheSchemaIsTheTables) {
  const auto table = table_bounds();
  const std::vector<SchemaBound> schema = BoundCollector(load_schema()).collect();
  ASSERT_FALSE(schema.empty());
  for (const auto& bound : schema) {
    const auto entry = table.find(bound.path);
    if (entry == table.end()) {
      ADD_FAILURE() << "the schema bounds " << bound.path << " (" << bound.keyword << " "
                    << bound.value << "), the table does not";
      continue;
    }
    const auto expected = entry->second.find(bound.keyword);
    if (expected == entry->second.end()) {
      ADD_FAILURE() << bound.path << ": the schema has " << bound.keyword << ", the table does not";
      continue;
    }
    EXPECT_TRUE(same(bound.value, expected->second))
        << bound.path << " " << bound.keyword << ": schema " << bound.value << ", table "
        << expected->second;
  }
}

// The schema's bounds are in the unit of the bare number its $def gives the value: that $def must
// be the table's kind.
TEST(Limits, TheSchemaSpellsEachQuantityOfItsKind) {
  const std::vector<SchemaBound> schema = BoundCollector(load_schema()).collect();
  const std::set<std::string> quantity_defs = {"number", "length",      "angle",
                                               "time",   "fnumber",     "temperature",
                                               "power",  "illuminance", "angular_velocity"};
  for (const auto& limit : limits::kQuantities) {
    for (const auto& bound : schema) {
      if (bound.path != limit.path) continue;
      for (const auto& def : bound.defs) {
        const std::string quantity = def.rfind("vec3_", 0) == 0 ? def.substr(5) : def;
        if (!quantity_defs.count(quantity)) continue;
        EXPECT_EQ(quantity, def_of(limit.kind)) << limit.path;
      }
    }
  }
}

}  // namespace
}  // namespace rigc
