#include "eval/inputs.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "assets/mesh_io.h"
#include "compiler/frontend.h"
#include "eval/raw_photos.h"
#include "io/input_files.h"
#include "ir/utf8_text.h"
#include "run/manifest.h"
#include "run/scene_inputs.h"

namespace rigc::eval {

namespace fs = std::filesystem;
using nlohmann::json;

bool ImageSet::one_size() const {
  return std::all_of(size.begin(), size.end(),
                     [&](const auto& entry) { return entry.second == size.begin()->second; });
}

bool every_image_planned(const std::vector<std::string>& image_names,
                         const std::map<std::string, ir::Mat4>& planned_poses) {
  return std::all_of(image_names.begin(), image_names.end(),
                     [&](const std::string& name) { return planned_poses.count(name) > 0; });
}

std::vector<ir::Vec3> planned_eyes(const ir::Scene& scene) {
  std::vector<ir::Vec3> eyes;
  for (const ir::Shot& shot : scene.shots)
    eyes.push_back(shot.object_from_camera.block<3, 1>(0, 3));
  return eyes;
}

namespace {

bool is_image_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".tif" || ext == ".tiff" ||
         is_raw_photo(p);
}

std::vector<std::string> list_images(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (e.is_regular_file() && is_image_file(e.path())) names.push_back(e.path().filename());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// A photo larger than this is refused from its header: COLMAP decodes each image whole (a header
// claiming 60000 x 60000 pixels made it allocate 10.5 GB and abort). A 150 MP medium-format frame
// is well inside.
constexpr double kMostPhotoPixels = 250e6;

// Why OIIO cannot read the last row of an open image, or "": a file whose header is intact but
// whose pixel data is missing or cut short. Raw photos are developed (and checked) later.
std::string last_row_problem(OIIO::ImageInput& input, const fs::path& path) {
  const OIIO::ImageSpec& spec = input.spec();
  if (is_raw_photo(path) || spec.tile_width > 0) return "";
  std::vector<float> row(static_cast<std::size_t>(spec.width) * spec.nchannels);
  if (input.read_scanline(spec.y + spec.height - 1, 0, OIIO::TypeDesc::FLOAT, row.data())) {
    return "";
  }
  std::string why = input.geterror();
  std::replace(why.begin(), why.end(), '\n', ' ');
  return fmt::format("cannot be decoded ({})", why.empty() ? "its pixel data is cut short" : why);
}

// Why a JPEG or PNG file does not end as a whole one does, or "": libjpeg decodes a JPEG cut short
// with a warning and grey rows, so its last row reads well. A JPEG ends with the end-of-image
// marker FF D9 (after which some writers pad with zero bytes), a PNG with its IEND chunk. Reads
// the last 4 KB only.
std::string cut_short_problem(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  const bool jpeg = ext == ".jpg" || ext == ".jpeg";
  if (!jpeg && ext != ".png") return "";
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = in.tellg();
  const std::streamoff tail_size = std::min<std::streamoff>(size, 4096);
  std::string tail(static_cast<std::size_t>(std::max<std::streamoff>(tail_size, 0)), '\0');
  in.seekg(size - tail_size);
  if (!in.read(tail.data(), tail_size)) return "";  // unreadable: OpenImageIO says why
  if (jpeg) {
    const std::size_t end = tail.find_last_not_of('\0');
    if (end != std::string::npos && end >= 1 && tail.compare(end - 1, 2, "\xFF\xD9") == 0)
      return "";
    return "is cut short (a JPEG ends with the end-of-image marker FF D9; this one does not)";
  }
  static const std::string kIend("\0\0\0\0IEND\xAE\x42\x60\x82", 12);
  if (tail.size() >= kIend.size() && tail.ends_with(kIend)) return "";
  return "is cut short (a PNG ends with its IEND chunk; this one does not)";
}

// Why the image at `path` cannot go to COLMAP, or "" with its size set in `set`. `decode` also
// reads its last row, for photos that rigc did not write itself.
std::string image_problem(ImageSet& set, const std::string& name, bool decode) {
  const fs::path path = set.dir / name;
  auto input = OIIO::ImageInput::open(path.string());
  if (!input) {
    std::string why = OIIO::geterror();
    std::replace(why.begin(), why.end(), '\n', ' ');
    return why;
  }
  const OIIO::ImageSpec& spec = input->spec();
  if (static_cast<double>(spec.width) * spec.height > kMostPhotoPixels) {
    return fmt::format(
        "its header says {} x {} pixels, more than the {:.0f} megapixels a photo "
        "may have",
        spec.width, spec.height, kMostPhotoPixels / 1e6);
  }
  if (decode) {
    if (std::string problem = cut_short_problem(path); !problem.empty()) return problem;
    if (std::string problem = last_row_problem(*input, path); !problem.empty()) return problem;
  }
  set.size[name] = {spec.width, spec.height};
  if (spec.format != OIIO::TypeDesc::UINT8) set.wider_than_eight_bit.insert(name);
  return "";
}

// Every image's header (and for photos its data), read before COLMAP runs: its feature extractor
// only logs a file it cannot read, its matcher then aborts without naming the file, and a header
// claiming gigapixels exhausts memory. False with `error` listing the unreadable ones.
bool read_headers(ImageSet& set, bool decode, std::string* error) {
  std::vector<std::string> unreadable;
  for (const auto& name : set.names) {
    const std::string why = image_problem(set, name, decode);
    if (!why.empty()) unreadable.push_back(fmt::format("{}: {}", (set.dir / name).string(), why));
  }
  if (unreadable.empty()) return true;
  *error =
      fmt::format("{} of the {} images cannot be read; remove or replace {}:", unreadable.size(),
                  set.names.size(), unreadable.size() == 1 ? "it" : "them");
  constexpr std::size_t kListed = 10;
  for (std::size_t i = 0; i < std::min(kListed, unreadable.size()); ++i) {
    *error += "\n  " + unreadable[i];
  }
  if (unreadable.size() > kListed) {
    *error += fmt::format("\n  and {} more", unreadable.size() - kListed);
  }
  return false;
}

// The images of a run folder (RUN/images) or of a photos folder (PHOTOS/images, else PHOTOS).
std::optional<ImageSet> find_images(const fs::path& run_dir, bool photos, std::string* error) {
  ImageSet set;
  set.dir = run_dir / "images";
  if (photos && !fs::is_directory(set.dir)) set.dir = run_dir;
  std::error_code exists_ec;
  if (!fs::exists(run_dir, exists_ec)) {
    *error = fmt::format("{} does not exist", run_dir.string());
    return std::nullopt;
  }
  if (!fs::is_directory(set.dir)) {
    *error = fmt::format("{} has no images/ folder (is it a run folder?)", run_dir.string());
    return std::nullopt;
  }
  set.names = list_images(set.dir);
  // eval.json and COLMAP's text model hold the names: a name that is not UTF-8 ended eval in an
  // internal error after COLMAP had run.
  for (const auto& name : set.names) {
    if (valid_utf8(name)) continue;
    *error = fmt::format(
        "{}: the file name '{}' is not valid UTF-8; rename it (eval's reports "
        "are JSON, which holds UTF-8 text only)",
        set.dir.string(), valid_utf8_text(name));
    return std::nullopt;
  }
  if (set.names.size() < 2) {
    *error =
        fmt::format("{} has {} image(s); SfM needs at least 2", set.dir.string(), set.names.size());
    return std::nullopt;
  }
  if (!read_headers(set, photos, error)) return std::nullopt;
  for (const auto& name : set.names) {
    protect_input_file(set.dir / name, photos ? "a photo" : "an image of the run");
  }
  return set;
}

// The scene file a run was rendered from: manifest.json's inputs.source_file.
std::optional<std::string> scene_of_run(const fs::path& run_dir, const json& manifest,
                                        std::string* error) {
  const fs::path manifest_path = run_dir / "manifest.json";
  if (!fs::exists(manifest_path)) {
    *error = fmt::format(
        "no ground truth: {} has no manifest.json naming its scene; pass --ground-truth MESH "
        "or --scene FILE",
        run_dir.string());
    return std::nullopt;
  }
  if (manifest.is_discarded()) {
    *error = fmt::format(
        "no ground truth: {} is not valid JSON; pass --ground-truth MESH or --scene FILE",
        manifest_path.string());
    return std::nullopt;
  }
  const json& m = manifest;
  if (!m.is_object() || !m.contains("inputs") || !m["inputs"].is_object() ||
      !m["inputs"].contains("source_file") || !m["inputs"]["source_file"].is_string()) {
    *error = fmt::format(
        "no ground truth: {} has no inputs.source_file; pass --ground-truth MESH or --scene FILE",
        manifest_path.string());
    return std::nullopt;
  }
  const std::string scene_path = m["inputs"]["source_file"].get<std::string>();
  if (fs::path(scene_path).is_relative() && !fs::exists(scene_path)) {
    *error = fmt::format(
        "no ground truth: the run's scene '{}' (manifest.json, relative to where it was "
        "rendered) is not found from here; pass --scene FILE or --ground-truth MESH",
        scene_path);
    return std::nullopt;
  }
  return scene_path;
}

// The object of a scene file, in the object frame. `warning` is set when the run's manifest
// records another object: numbers measured against it would have no meaning.
bool load_scene_object(const std::string& scene_path, const fs::path& run_dir, const json& manifest,
                       GroundTruth& gt, std::string* error, std::string* warning) {
  DiagnosticEngine diag;
  std::string messages;
  diag.set_handler([&](const Diagnostic& d, const std::string& text) {
    if (d.severity == Severity::kError) messages += text;
  });
  auto scene = compile_scene_file(scene_path, diag);
  if (!scene) {
    *error =
        fmt::format("cannot compile the scene {} for its ground truth:\n{}", scene_path, messages);
    return false;
  }
  run::protect_scene_inputs(scene_path, *scene);
  gt.positions = ir::object_frame_positions(scene->object);
  gt.triangles = scene->object.mesh.triangles;
  gt.description = fmt::format("{} object ({}), object frame", scene_path, scene->object.source);
  if (scene->studio.backdrop.green_screen) gt.backdrop_color = scene->studio.backdrop.color;
  gt.planned_eyes = planned_eyes(*scene);
  const json& m = manifest;
  if (m.is_object() && m.contains("inputs") && m["inputs"].is_object() &&
      m["inputs"].contains("object_sha256") && m["inputs"]["object_sha256"].is_string() &&
      m["inputs"]["object_sha256"].get<std::string>() != run::object_geometry_hash(*scene)) {
    *warning = fmt::format(
        "the object of {} is not the one the run in {} was rendered with (its surface differs "
        "from manifest.json's object_sha256): the numbers measure against another object",
        scene_path, run_dir.string());
  }
  return true;
}

// The ground-truth mesh: --ground-truth (its own frame), else the object of --scene or of the
// run's scene.
bool load_ground_truth_mesh(const EvalOptions& o, const fs::path& run_dir, bool photos,
                            GroundTruth& gt, std::string* error, std::string* warning) {
  if (!o.ground_truth.empty()) {
    auto model = load_model(o.ground_truth, error);
    if (!model) return false;
    protect_input_file(o.ground_truth, "the ground-truth mesh");
    gt.positions = std::move(model->mesh.positions);
    gt.triangles = std::move(model->mesh.triangles);
    gt.description = fmt::format("{} (its own frame)", o.ground_truth);
  } else {
    const json manifest =
        photos ? json()
               : json::parse(std::ifstream(run_dir / "manifest.json", std::ios::binary), nullptr,
                             false);
    std::string scene_path = o.scene;
    if (scene_path.empty()) {
      auto from_run = scene_of_run(run_dir, manifest, error);
      if (!from_run) return false;
      scene_path = *from_run;
    }
    if (!load_scene_object(scene_path, run_dir, manifest, gt, error, warning)) return false;
  }
  if (gt.triangles.empty()) {
    *error = "the ground-truth mesh has no triangles";
    return false;
  }
  return true;
}

// A run's planned cameras (sparse/images.txt and cameras.txt), which must fit the images: COLMAP
// takes this camera as every image's intrinsics, and a size that is not the images' own makes it
// fail or exhaust the memory.
bool load_planned_cameras(const fs::path& run_dir, const ImageSet& images, GroundTruth& gt,
                          std::string* error) {
  const fs::path sparse = run_dir / "sparse";
  auto planned = run::read_colmap_images(sparse / "images.txt", error);
  if (!planned) return false;
  auto cameras = run::read_colmap_cameras(sparse / "cameras.txt", error);
  if (!cameras || !run::check_camera_ids(*planned, *cameras, sparse / "images.txt", error)) {
    return false;
  }
  for (const char* file : {"images.txt", "cameras.txt", "points3D.txt"}) {
    protect_input_file(sparse / file, "the run's ground-truth cameras");
  }
  for (const auto& im : *planned) gt.poses[im.name] = im.camera_from_world;
  gt.camera = cameras->front();
  for (const auto& [name, size] : images.size) {
    if (size != std::pair{gt.camera->width, gt.camera->height}) {
      *error = fmt::format("{} is {}x{} pixels, but {} gives the camera as {}x{}",
                           (images.dir / name).string(), size.first, size.second,
                           (sparse / "cameras.txt").string(), gt.camera->width, gt.camera->height);
      return false;
    }
  }
  return true;
}

// Ground truth: mesh, and camera poses when the run has them (world = object frame).
std::optional<GroundTruth> load_ground_truth(const EvalOptions& o, const fs::path& run_dir,
                                             bool photos, const ImageSet& images, std::ostream& log,
                                             std::string* error) {
  GroundTruth gt;
  if (photos && o.ground_truth.empty() && o.scene.empty()) {
    if (!o.imported.reconstruction.empty() || o.metrics.poisson) {
      *error = fmt::format(
          "{} measures against a ground-truth mesh: give --ground-truth MESH or "
          "--scene FILE",
          o.metrics.poisson ? "--poisson" : "--reconstruction");
      return std::nullopt;
    }
    gt.description = "none (photos without a ground-truth mesh: registration only)";
    return gt;
  }
  std::string warning;
  if (!load_ground_truth_mesh(o, run_dir, photos, gt, error, &warning)) return std::nullopt;
  if (!warning.empty()) log << "rigc eval: warning: " << warning << "\n";
  if (!photos && fs::exists(run_dir / "sparse" / "images.txt") &&
      !load_planned_cameras(run_dir, images, gt, error)) {
    return std::nullopt;
  }
  return gt;
}

// What COLMAP needs of the images beyond being readable.
bool check_images_for_colmap(const EvalOptions& o, const ImageSet& images, const GroundTruth& truth,
                             std::ostream& log, std::string* error) {
  // SIFT finds nothing in a thumbnail: the input's fault, not a tool failure.
  constexpr int kSmallestSide = 32;
  for (const auto& [name, size] : images.size) {
    if (std::min(size.first, size.second) < kSmallestSide) {
      *error = fmt::format("{} is {}x{} pixels: too small to find features in (at least {} a side)",
                           (images.dir / name).string(), size.first, size.second, kSmallestSide);
      return false;
    }
  }
  if (!images.one_size() && !o.quiet) {
    log << "rigc eval: the photos differ in size: COLMAP gets one camera per photo\n";
  }
  if (o.sfm.matcher == Matcher::neighbours && !every_image_planned(images.names, truth.poses)) {
    *error = fmt::format(
        "--matcher neighbours needs a planned pose for every image (a run folder's "
        "sparse/images.txt); {} has images without one",
        images.dir.string());
    return false;
  }
  return true;
}

// Names of `names` (at most three, then how many more), for a message.
std::string some_names(const std::vector<std::string>& names) {
  std::string text;
  for (std::size_t i = 0; i < names.size() && i < 3; ++i) text += (i ? ", " : "") + names[i];
  if (names.size() > 3) text += fmt::format(" and {} more", names.size() - 3);
  return text;
}

// --reference-cameras: a camera for every photo (more are a warning); intrinsics without a size
// take their photo's.
bool load_reference_cameras(const EvalOptions& o, EvalInputs& in, std::ostream& log,
                            std::string* error) {
  auto file = read_camera_file(o.photos.reference_cameras, error);
  if (!file) return false;
  KnownCameras known = known_cameras(*file);
  std::vector<std::string> missing, extra;
  for (const auto& name : in.images.names) {
    if (!known.count(name)) missing.push_back(name);
  }
  for (const auto& [name, camera] : known) {
    if (!in.images.size.count(name)) extra.push_back(name);
  }
  if (!missing.empty()) {
    std::vector<std::string> named;
    for (const auto& [name, camera] : known) named.push_back(name);
    *error = fmt::format(
        "{} has no camera for {} of the {} photos in {} ({}); its cameras are named {}",
        o.photos.reference_cameras, missing.size(), in.images.names.size(), in.images.dir.string(),
        some_names(missing), named.empty() ? "(none)" : some_names(named));
    return false;
  }
  if (!extra.empty() && !o.quiet) {
    log << fmt::format(
        "rigc eval: warning: {} has cameras for {} images not among the photos ({})\n",
        o.photos.reference_cameras, extra.size(), some_names(extra));
  }
  for (auto& [name, camera] : known) {
    const auto size = in.images.size.find(name);
    if (camera.intrinsics && camera.intrinsics->width == 0 && size != in.images.size.end()) {
      camera.intrinsics->width = size->second.first;
      camera.intrinsics->height = size->second.second;
    }
  }
  std::erase_if(known, [&](const auto& entry) { return !in.images.size.count(entry.first); });
  protect_input_file(o.photos.reference_cameras, "the reference cameras");
  in.reference = std::move(known);
  in.reference_description = fmt::format("{} ({})", o.photos.reference_cameras, file->format);
  return true;
}

}  // namespace

std::optional<EvalInputs> gather_inputs(const EvalOptions& o, std::ostream& log,
                                        EvalSummary& summary) {
  EvalInputs in;
  in.photos = !o.photos_dir.empty();
  in.run_dir = in.photos ? fs::path(o.photos_dir) : fs::path(o.run_dir);
  std::string error;
  auto refuse = [&] {
    log << "rigc eval: error: " << error << "\n";
    return std::nullopt;
  };
  auto images = find_images(in.run_dir, in.photos, &error);
  if (!images) return refuse();
  in.images = std::move(*images);
  summary.images = static_cast<int>(in.images.names.size());
  auto truth = load_ground_truth(o, in.run_dir, in.photos, in.images, log, &error);
  if (!truth) return refuse();
  in.truth = std::move(*truth);
  if (!check_images_for_colmap(o, in.images, in.truth, log, &error)) return refuse();
  if (!o.photos.reference_cameras.empty() && !load_reference_cameras(o, in, log, &error))
    return refuse();

  in.out = o.output_dir.empty() ? in.run_dir / "eval" : fs::path(o.output_dir);
  std::error_code ec;
  fs::create_directories(in.out, ec);
  if (!fs::is_directory(in.out)) {
    error = fmt::format("cannot create the output folder {}", in.out.string());
    return refuse();
  }
  summary.output_dir = in.out.string();
  if (in.photos && !develop_raw_photos(in.images, in.out, log, o.quiet, &error)) return refuse();
  return in;
}

}  // namespace rigc::eval
