// What COLMAP's database (database.db, SQLite) says of the images it extracted features from:
// their ids, names and cameras, which a model of known poses must use (point_triangulator
// matches the model's images to the database's by id).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rigc::eval {

struct DatabaseImage {
  int image_id = 0;
  int camera_id = 0;
  std::string name;
};

struct DatabaseCamera {
  int camera_id = 0;
  int width = 0, height = 0;
};

struct DatabaseContents {
  std::vector<DatabaseImage> images;
  std::vector<DatabaseCamera> cameras;
};

// Reads the images and cameras tables (read-only). nullopt with a one-line error naming the file.
std::optional<DatabaseContents> read_colmap_database(const std::filesystem::path& path,
                                                     std::string* error);

}  // namespace rigc::eval
