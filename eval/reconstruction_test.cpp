#include "eval/reconstruction.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/PointCloudIO.h>
#include <open3d/io/TriangleMeshIO.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "assets/mesh_io.h"
#include "assets/primitives.h"
#include "eval/align.h"
#include "eval/reconstruction_test_support.h"

using ::testing::HasSubstr;

namespace rigc::eval {
namespace {

namespace fs = std::filesystem;
using test_inputs::make_statue_run;
using test_inputs::StatueRun;

// The tool's frame: the object scaled, turned and moved.
Similarity tool_from_object() {
  Similarity s;
  s.scale = 1.7;
  s.rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  s.translation = Vec3(0.3, -0.2, 0.5);
  return s;
}

// The ground truth as a triangle soup, each triangle moved along its normal by a normal deviate
// of `sigma_m` (so every sample of it lies that far from the ground truth), then put in `frame`.
ir::Mesh noisy_soup(const StatueRun& r, double sigma_m, const Similarity& frame) {
  const auto positions = ir::object_frame_positions(r.scene.object);
  std::mt19937_64 random(5);
  std::normal_distribution<double> noise(0, sigma_m);
  ir::Mesh soup;
  for (const auto& t : r.scene.object.mesh.triangles) {
    const Vec3 a = positions[t[0]].cast<double>(), b = positions[t[1]].cast<double>(),
               c = positions[t[2]].cast<double>();
    const Vec3 offset = (b - a).cross(c - a).normalized() * noise(random);
    const auto first = static_cast<std::uint32_t>(soup.positions.size());
    for (const Vec3& p : {a, b, c}) soup.positions.push_back(frame.apply(p + offset).cast<float>());
    soup.triangles.push_back({first, first + 1, first + 2});
  }
  return soup;
}

// The run's cameras as the tool would export them in its frame: Bundler.
void write_moved_bundler(const StatueRun& r, const Similarity& frame, const fs::path& out) {
  ir::Scene moved = r.scene;
  for (auto& shot : moved.shots) {
    const ir::Mat4 pose = shot.object_from_camera;
    shot.object_from_camera.topLeftCorner<3, 3>() = frame.rotation * pose.topLeftCorner<3, 3>();
    shot.object_from_camera.topRightCorner<3, 1>() = frame.apply(pose.topRightCorner<3, 1>());
  }
  std::string error;
  ASSERT_TRUE(run::write_bundler(out, fs::path(out).replace_extension(".list.txt"), moved, r.shots,
                                 test_inputs::kStatueScale, {}, &error))
      << error;
}

EvalOptions reconstruction_options(const StatueRun& r, const std::string& file,
                                   const fs::path& out) {
  EvalOptions o;
  o.run_dir = r.dir.string();
  o.scene = r.scene_file.string();
  o.imported.reconstruction = file;
  o.output_dir = out.string();
  o.quiet = true;
  o.metrics.ground_truth_samples = 20000;
  o.imported.mesh_samples = 100000;
  return o;
}

// How far the found alignment is from undoing `frame`: the largest move of a ground-truth vertex
// (m) and the rotation left (deg).
std::pair<double, double> alignment_error(const StatueRun& r, const nlohmann::json& report,
                                          const Similarity& frame) {
  Mat4 m;
  const auto& rows = report["alignment"]["reconstruction_to_ground_truth"]["matrix"];
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) m(i, j) = rows[i][j].get<double>();
  }
  const Similarity round_trip = Similarity::from_matrix(m) * frame;
  double worst = 0;
  for (const auto& p : ir::object_frame_positions(r.scene.object)) {
    worst = std::max(worst, (round_trip.apply(p.cast<double>()) - p.cast<double>()).norm());
  }
  return {worst, rotation_angle_deg(round_trip.rotation)};
}

TEST(EvalReconstruction, MovedNoisyMeshIsAlignedBackOnItsCamerasAndItsNoiseMeasured) {
  rigc::testing::TempDir dir;
  const auto r = make_statue_run(dir.path(), 500);
  ASSERT_TRUE(r);
  constexpr double kSigma = 0.3e-3;
  const Similarity frame = tool_from_object();
  std::string error;
  ASSERT_TRUE(write_ply(dir.file("mesh.ply"), noisy_soup(*r, kSigma, frame), &error)) << error;
  write_moved_bundler(*r, frame, dir.path() / "tool.out");
  EvalOptions o = reconstruction_options(*r, dir.file("mesh.ply"), dir.path() / "eval");
  o.imported.cameras = dir.file("tool.out");
  std::ostringstream log;
  EvalSummary s;
  ASSERT_EQ(evaluate(o, log, &s), 0) << log.str();
  EXPECT_EQ(s.report["reconstruction"]["kind"], "mesh");
  EXPECT_EQ(s.report["reconstruction"]["cameras"]["format"], "Bundler");
  EXPECT_EQ(s.report["compared"], "mesh_samples");
  const auto [move_m, turn_deg] = alignment_error(*r, s.report, frame);
  EXPECT_LT(move_m, 0.1e-3);
  EXPECT_LT(turn_deg, 0.1);
  EXPECT_NEAR(s.std_mm, kSigma * 1000, 0.1 * kSigma * 1000) << s.report["signed_distance_mm"];
  EXPECT_NEAR(s.mean_mm, 0, 0.1 * kSigma * 1000);
  // Recall against the mesh itself: every visible ground-truth sample is within 1 mm of it.
  EXPECT_GT(s.report["fscore"]["recall"].get<double>(), 0.98);
  // The cameras are the ground truth's, moved with the mesh: what is left is ICP settling the
  // noisy mesh (0.01 deg turns a camera 70 cm away by 0.12 mm).
  EXPECT_LT(s.report["cameras"]["position_error_mm"]["max"].get<double>(), 0.5);
  EXPECT_TRUE(fs::exists(dir.path() / "eval" / "heatmap.png"));
}

TEST(EvalReconstruction, MovedNoisyMeshIsRegisteredBackWithoutCameras) {
  rigc::testing::TempDir dir;
  const auto r = make_statue_run(dir.path(), 500);
  ASSERT_TRUE(r);
  constexpr double kSigma = 0.3e-3;
  const Similarity frame = tool_from_object();
  std::string error;
  ASSERT_TRUE(write_ply(dir.file("mesh.ply"), noisy_soup(*r, kSigma, frame), &error)) << error;
  const EvalOptions o = reconstruction_options(*r, dir.file("mesh.ply"), dir.path() / "eval");
  std::ostringstream log;
  EvalSummary s;
  ASSERT_EQ(evaluate(o, log, &s), 0) << log.str();
  EXPECT_GT(s.report["alignment"]["fitness"]["value"].get<double>(), 0.95);
  const auto [move_m, turn_deg] = alignment_error(*r, s.report, frame);
  EXPECT_LT(move_m, 0.1e-3);
  EXPECT_LT(turn_deg, 0.1);
  EXPECT_NEAR(s.std_mm, kSigma * 1000, 0.1 * kSigma * 1000) << s.report["signed_distance_mm"];
  // Every RANSAC start was refined and scored; the one kept lies closest to the surface.
  const auto& alignment = s.report["alignment"];
  ASSERT_EQ(alignment["starts"].size(), 4u) << alignment;
  const double chosen = alignment["chosen"]["clipped_mean_distance_mm"].get<double>();
  for (const auto& start : alignment["starts"]) {
    EXPECT_LE(chosen, start["clipped_mean_distance_mm"].get<double>()) << alignment;
  }
  EXPECT_LT(chosen, 3 * kSigma * 1000) << alignment;
}

// A cloud of another object (a box where the statue should be) registers poorly: refused, with
// the registration's fitness on the log and in eval.json.
TEST(EvalReconstruction, ACloudOfAnotherObjectIsRefusedWithItsFitness) {
  rigc::testing::TempDir dir;
  const auto r = make_statue_run(dir.path(), 500);
  ASSERT_TRUE(r);
  ir::Mesh box = make_primitive(PrimitiveKind::kBox, 4, 1);
  for (auto& p : box.positions) p = 0.2f * p + Eigen::Vector3f(0, 0, 0.1f);
  std::vector<Vec3> samples, normals;
  Surface(box.positions, box.triangles).sample(20000, 3, &samples, &normals);
  open3d::geometry::PointCloud cloud;
  cloud.points_ = samples;
  ASSERT_TRUE(open3d::io::WritePointCloud(dir.file("box.ply"), cloud));
  const EvalOptions o = reconstruction_options(*r, dir.file("box.ply"), dir.path() / "eval");
  std::ostringstream log;
  EvalSummary s;
  EXPECT_EQ(evaluate(o, log, &s), 2);
  EXPECT_THAT(log.str(), HasSubstr("the registration fits poorly (fitness 0."));
  const auto report = nlohmann::json::parse(std::ifstream(dir.path() / "eval" / "eval.json"));
  EXPECT_EQ(report["alignment"]["status"], "failed");
  EXPECT_LT(report["alignment"]["fitness"]["value"].get<double>(), 0.5);
}

// Points already in the scene's frame (the run's own ground-truth points) measure as exact.
TEST(EvalReconstruction, PointsInTheScenesFrameNeedNoAlignment) {
  rigc::testing::TempDir dir;
  const auto r = make_statue_run(dir.path(), 3000);
  ASSERT_TRUE(r);
  open3d::geometry::PointCloud cloud;
  for (const auto& p : r->points.points) {
    cloud.points_.push_back(p.position);
    cloud.colors_.push_back(Vec3(p.rgb[0], p.rgb[1], p.rgb[2]) / 255);
  }
  open3d::io::WritePointCloudOption ascii;
  ascii.write_ascii = open3d::io::WritePointCloudOption::IsAscii::Ascii;
  ASSERT_TRUE(open3d::io::WritePointCloud(dir.file("points.ply"), cloud, ascii));
  EvalOptions o = reconstruction_options(*r, dir.file("points.ply"), dir.path() / "eval");
  o.imported.align = false;
  std::ostringstream log;
  EvalSummary s;
  ASSERT_EQ(evaluate(o, log, &s), 0) << log.str();
  EXPECT_EQ(s.points, static_cast<long>(r->points.points.size()));
  EXPECT_LT(s.report["signed_distance_mm"]["max"].get<double>(), 1e-3);
  EXPECT_NEAR(s.report["fscore"]["precision"].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(s.report["reconstruction"]["colors"], true);
  EXPECT_THAT(s.report["alignment"]["method"].get<std::string>(), HasSubstr("--no-align"));
}

// Every format a tool exports loads, mesh or cloud, binary or ASCII, with or without colours and
// normals.
TEST(EvalReconstruction, LoadsMeshesAndCloudsInEveryFormat) {
  rigc::testing::TempDir dir;
  open3d::geometry::TriangleMesh mesh = *open3d::geometry::TriangleMesh::CreateBox(0.1, 0.2, 0.3);
  ASSERT_EQ(mesh.triangles_.size(), 12u);
  mesh.ComputeVertexNormals();
  for (const char* name : {"m.obj", "m.stl", "m.glb", "m.gltf"}) {
    ASSERT_TRUE(open3d::io::WriteTriangleMesh(dir.file(name), mesh)) << name;
  }
  open3d::io::WriteTriangleMesh(dir.file("ascii.ply"), mesh, /*write_ascii=*/true);
  open3d::geometry::PointCloud cloud;
  for (int i = 0; i < 100; ++i) cloud.points_.push_back(Vec3(i * 0.01, 0.5, -0.2));
  ASSERT_TRUE(open3d::io::WritePointCloud(dir.file("plain.ply"), cloud));
  ASSERT_TRUE(open3d::io::WritePointCloud(dir.file("plain.xyz"), cloud));
  cloud.colors_.assign(100, Vec3(1, 0, 0));
  cloud.normals_.assign(100, Vec3(0, 0, 1));
  open3d::io::WritePointCloudOption ascii;
  ascii.write_ascii = open3d::io::WritePointCloudOption::IsAscii::Ascii;
  ASSERT_TRUE(open3d::io::WritePointCloud(dir.file("rich.ply"), cloud, ascii));
  ASSERT_TRUE(open3d::io::WritePointCloud(dir.file("rich_binary.ply"), cloud));
  std::string error;
  for (const char* name : {"m.obj", "m.stl", "m.glb", "m.gltf", "ascii.ply"}) {
    const auto g = load_reconstruction(dir.file(name), &error);
    ASSERT_TRUE(g) << name << ": " << error;
    EXPECT_EQ(g->triangles.size(), 12u) << name;
  }
  for (const char* name : {"plain.ply", "plain.xyz", "rich.ply", "rich_binary.ply"}) {
    const auto g = load_reconstruction(dir.file(name), &error);
    ASSERT_TRUE(g) << name << ": " << error;
    EXPECT_FALSE(g->is_mesh());
    ASSERT_EQ(g->points.size(), 100u) << name;
    EXPECT_NEAR(g->points[7].x(), 0.07, 1e-6);
  }
  EXPECT_TRUE(load_reconstruction(dir.file("rich.ply"), &error)->has_colors);
  EXPECT_TRUE(load_reconstruction(dir.file("rich.ply"), &error)->has_normals);
  EXPECT_TRUE(load_reconstruction(dir.file("rich_binary.ply"), &error)->has_colors);
  EXPECT_FALSE(load_reconstruction(dir.file("plain.ply"), &error)->has_colors);
  // A binary cloud cut short.
  const std::string whole = rigc::testing::read_text(dir.file("rich_binary.ply"));
  rigc::testing::write_text(dir.file("cut.ply"), whole.substr(0, whole.size() - 100));
  EXPECT_FALSE(load_reconstruction(dir.file("cut.ply"), &error));
  EXPECT_THAT(error, HasSubstr("cut.ply: announces 100 vertex elements"));
  // A header that claims a trillion points is refused before anything is allocated for them.
  rigc::testing::write_text(dir.file("huge.ply"),
                            "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n"
                            "property float x\nproperty float y\nproperty float z\nend_header\n" +
                                std::string(120, '\0'));
  EXPECT_FALSE(load_reconstruction(dir.file("huge.ply"), &error));
  EXPECT_THAT(error, HasSubstr("announces 1000000000000 vertex elements"));
  // Non-finite points are left out and counted.
  std::string nan_cloud =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  for (float v : {0.1f, 0.2f, 0.3f, std::nanf(""), 0.f, 0.f, 0.4f, 0.5f, 0.6f}) {
    nan_cloud.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  rigc::testing::write_text(dir.file("nan.ply"), nan_cloud);
  const auto with_nan = load_reconstruction(dir.file("nan.ply"), &error);
  ASSERT_TRUE(with_nan) << error;
  ASSERT_EQ(with_nan->points.size(), 2u);
  EXPECT_EQ(with_nan->dropped, 1u);
  EXPECT_NEAR(with_nan->points[1].z(), 0.6, 1e-6);
  // Bad files: named, never a crash.
  rigc::testing::write_text(dir.file("junk.ply"), "ply\nnot really\n");
  EXPECT_FALSE(load_reconstruction(dir.file("junk.ply"), &error));
  EXPECT_THAT(error, HasSubstr("junk.ply"));
  EXPECT_FALSE(load_reconstruction(dir.file("m.fbx"), &error));
  rigc::testing::write_text(dir.file("m.las"), "x");
  EXPECT_FALSE(load_reconstruction(dir.file("m.las"), &error));
  EXPECT_THAT(error, HasSubstr("unknown reconstruction format"));
}

// Headers are held to the file's size before any reader allocates (a 117-byte PCD claiming
// 100,000,000 points took 9.2 GB), and a mesh without area is named (it was Open3D's "Invalid
// surface area" as an internal error).
TEST(EvalReconstruction, HeadersThatClaimMoreThanTheFileAndFlatMeshesAreNamed) {
  rigc::testing::TempDir dir;
  const std::string pcd_head =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
      "WIDTH 100000000\nHEIGHT 1\nPOINTS 100000000\n";
  rigc::testing::write_text(dir.file("ascii.pcd"), pcd_head + "DATA ascii\n0 0 0\n");
  rigc::testing::write_text(dir.file("binary.pcd"),
                            pcd_head + "DATA binary\n" + std::string(12, '\0'));
  rigc::testing::write_text(dir.file("big.ply"),
                            "ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\n"
                            "property float x\nproperty float y\nproperty float z\nend_header\n"
                            "0 0 0\n");
  std::string stl(80, ' ');
  const std::uint32_t triangles = 1000000000;
  stl.append(reinterpret_cast<const char*>(&triangles), 4);
  rigc::testing::write_text(dir.file("big.stl"), stl + std::string(50, '\0'));
  rigc::testing::write_text(dir.file("big.pts"), "1000000000000\n0 0 0\n");
  std::string error;
  for (const char* name : {"ascii.pcd", "binary.pcd", "big.ply", "big.stl", "big.pts"}) {
    EXPECT_FALSE(load_reconstruction(dir.file(name), &error)) << name;
    EXPECT_THAT(error, HasSubstr(std::string(name) + ": announces "));
    EXPECT_THAT(error, HasSubstr("bytes after its header"));
  }
  rigc::testing::write_text(dir.file("flat.ply"),
                            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                            "property float y\nproperty float z\nelement face 1\n"
                            "property list uchar int vertex_indices\nend_header\n"
                            "0 0 0\n1 1 1\n2 2 2\n3 0 1 2\n");
  EXPECT_FALSE(load_reconstruction(dir.file("flat.ply"), &error));
  EXPECT_THAT(error, HasSubstr("flat.ply: its 1 faces have no area"));
}

TEST(EvalReconstruction, OptionsThatGoTogether) {
  EvalOptions o;
  o.run_dir = "run";
  std::string error;
  o.imported.cameras = "c.out";
  EXPECT_FALSE(o.check(&error));
  EXPECT_THAT(error, HasSubstr("go with --reconstruction"));
  o.imported.reconstruction = "r.ply";
  o.imported.align = false;
  EXPECT_FALSE(o.check(&error));
  EXPECT_THAT(error, HasSubstr("not both"));
  o.imported.cameras.clear();
  EXPECT_TRUE(o.check(&error)) << error;
  o.imported.min_fitness = 1.5;
  EXPECT_FALSE(o.check(&error));
}

// rigc compare's rows of other tools' results: NAME=FILE, a name fit for a folder.
TEST(EvalReconstruction, CompareRefusesMalformedReconstructionRows) {
  using rigc::testing::run_rigc;
  auto r = run_rigc({"compare", "scene.yaml", "--reconstruction", "no-equals-sign"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("'no-equals-sign' is not NAME=FILE"));
  r = run_rigc({"compare", "scene.yaml", "--reconstruction", "../x=a.ply"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("use letters, digits"));
  r = run_rigc({"compare", "scene.yaml", "--reconstruction", "a=a.ply", "--reconstruction-cameras",
                "b=b.out"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("which no --reconstruction does"));
}

}  // namespace
}  // namespace rigc::eval
