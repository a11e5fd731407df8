#include "eval/colmap_database.h"

#include <fmt/format.h>
#include <sqlite3.h>

#include <memory>

namespace rigc::eval {

namespace {

struct CloseDatabase {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
struct FinalizeStatement {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Database = std::unique_ptr<sqlite3, CloseDatabase>;
using Statement = std::unique_ptr<sqlite3_stmt, FinalizeStatement>;

// Runs `sql` and hands each row to `row`; false with `error` when SQLite refuses.
template <typename Row>
bool for_each_row(sqlite3* db, const char* sql, Row row, std::string* error) {
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db, sql, -1, &raw, nullptr) != SQLITE_OK) {
    *error = sqlite3_errmsg(db);
    return false;
  }
  const Statement statement(raw);
  int rc = SQLITE_OK;
  while ((rc = sqlite3_step(raw)) == SQLITE_ROW) row(raw);
  if (rc != SQLITE_DONE) {
    *error = sqlite3_errmsg(db);
    return false;
  }
  return true;
}

}  // namespace

std::optional<DatabaseContents> read_colmap_database(const std::filesystem::path& path,
                                                     std::string* error) {
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
  const Database db(raw);
  DatabaseContents contents;
  std::string why;
  const bool ok =
      rc == SQLITE_OK &&
      for_each_row(
          raw, "SELECT image_id, name, camera_id FROM images ORDER BY image_id",
          [&](sqlite3_stmt* s) {
            const auto* name = reinterpret_cast<const char*>(sqlite3_column_text(s, 1));
            contents.images.push_back(
                {sqlite3_column_int(s, 0), sqlite3_column_int(s, 2), name ? name : ""});
          },
          &why) &&
      for_each_row(
          raw, "SELECT camera_id, width, height FROM cameras ORDER BY camera_id",
          [&](sqlite3_stmt* s) {
            contents.cameras.push_back(
                {sqlite3_column_int(s, 0), sqlite3_column_int(s, 1), sqlite3_column_int(s, 2)});
          },
          &why);
  if (!ok) {
    *error = fmt::format("cannot read COLMAP's database {}: {}", path.string(),
                         why.empty() && raw ? sqlite3_errmsg(raw) : why);
    return std::nullopt;
  }
  return contents;
}

}  // namespace rigc::eval
