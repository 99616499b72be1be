// CGAL 5.5's Hausdorff distances on posed OBJ meshes, for `cargo bench --bench hausdorff`.
//
//   bench_cgal_hausdorff A.obj B.obj poses.txt --error E [--samples N]
//                        [--min-runs N] [--min-time S]
//
// poses.txt: one line per pose, 24 numbers: A's rotation (row-major) and translation, then
// B's. For each pose, one JSON line: the one-sided h(A, B) from
// Polygon_mesh_processing::bounded_error_Hausdorff_distance<Sequential_tag> at absolute
// error E and its median time (CGAL builds its AABB trees inside the call: they are timed),
// and, with --samples N > 0, approximate_Hausdorff_distance with N random points on A's
// faces (MeshLab's method; no bound) and its median time.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

struct Obj {
  std::vector<double> xyz;
  std::vector<size_t> tri;
};

static void fail(const std::string& what) {
  std::fprintf(stderr, "bench_cgal_hausdorff: %s\n", what.c_str());
  std::exit(1);
}

// Triangles only (the benchmark writes them), 1-based or negative indices, `i/j/k` forms.
static Obj read_obj(const char* path) {
  std::ifstream in(path);
  if (!in) fail(std::string("cannot read ") + path);
  Obj obj;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      double x, y, z;
      if (!(s >> x >> y >> z)) fail(std::string("bad vertex in ") + path);
      obj.xyz.insert(obj.xyz.end(), {x, y, z});
    } else if (tag == "f") {
      std::string word;
      std::vector<size_t> face;
      while (s >> word) {
        long i = std::strtol(word.c_str(), nullptr, 10);
        long n = static_cast<long>(obj.xyz.size() / 3);
        long k = i > 0 ? i - 1 : n + i;
        if (i == 0 || k < 0 || k >= n) fail(std::string("bad face index in ") + path);
        face.push_back(static_cast<size_t>(k));
      }
      if (face.size() != 3) fail(std::string("a face that is not a triangle in ") + path);
      obj.tri.insert(obj.tri.end(), face.begin(), face.end());
    }
  }
  return obj;
}

// The mesh posed by rotation r (row-major) and translation t.
static Mesh posed(const Obj& obj, const double* r, const double* t) {
  Mesh mesh;
  std::vector<Mesh::Vertex_index> v;
  for (size_t i = 0; i < obj.xyz.size(); i += 3) {
    const double* p = &obj.xyz[i];
    double q[3];
    for (int k = 0; k < 3; ++k) q[k] = r[3 * k] * p[0] + r[3 * k + 1] * p[1] + r[3 * k + 2] * p[2] + t[k];
    v.push_back(mesh.add_vertex(Point(q[0], q[1], q[2])));
  }
  for (size_t i = 0; i < obj.tri.size(); i += 3) {
    // A halfedge mesh cannot hold every soup (non-manifold edges): refuse rather than
    // answer for fewer faces than obbtree measures.
    if (mesh.add_face(v[obj.tri[i]], v[obj.tri[i + 1]], v[obj.tri[i + 2]]) == Mesh::null_face())
      fail("a face CGAL's Surface_mesh refuses (non-manifold input)");
  }
  return mesh;
}

// The median seconds of f over at least min_runs runs and min_time seconds, after one
// warm-up run.
template <class F>
static double median_time(F f, int min_runs, double min_time) {
  f();
  std::vector<double> times;
  double total = 0;
  while (static_cast<int>(times.size()) < min_runs || total < min_time) {
    auto t0 = std::chrono::steady_clock::now();
    f();
    double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    times.push_back(dt);
    total += dt;
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

static std::string num(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

int main(int argc, char** argv) {
  const char* usage =
      "usage: %s A.obj B.obj poses.txt --error E [--samples N] [--min-runs N] [--min-time S]\n";
  if (argc < 4) {
    std::fprintf(stderr, usage, argv[0]);
    return 1;
  }
  double error = -1, min_time = 0.02;
  int samples = 0, min_runs = 5;
  for (int i = 4; i + 1 < argc; i += 2) {
    std::string flag = argv[i];
    if (flag == "--error") error = std::atof(argv[i + 1]);
    else if (flag == "--samples") samples = std::atoi(argv[i + 1]);
    else if (flag == "--min-runs") min_runs = std::atoi(argv[i + 1]);
    else if (flag == "--min-time") min_time = std::atof(argv[i + 1]);
    else fail("unknown flag " + flag);
  }
  if (!(error > 0)) fail("--error must be above 0");
  Obj a = read_obj(argv[1]), b = read_obj(argv[2]);
  std::ifstream poses(argv[3]);
  if (!poses) fail(std::string("cannot read ") + argv[3]);
  std::string line;
  for (size_t index = 0; std::getline(poses, line); ++index) {
    std::istringstream s(line);
    double p[24];
    for (double& x : p)
      if (!(s >> x)) fail("pose line " + std::to_string(index + 1) + ": 24 numbers expected");
    Mesh ma = posed(a, p, p + 9), mb = posed(b, p + 12, p + 21);
    try {
      double bounded = 0;
      double bounded_s = median_time(
          [&] { bounded = PMP::bounded_error_Hausdorff_distance<CGAL::Sequential_tag>(ma, mb, error); },
          min_runs, min_time);
      std::printf("{\"pose\": %zu, \"tris_a\": %zu, \"tris_b\": %zu, \"error\": %s, \"bounded\": %s, \"bounded_s\": %s",
                  index, a.tri.size() / 3, b.tri.size() / 3, num(error).c_str(), num(bounded).c_str(),
                  num(bounded_s).c_str());
      if (samples > 0) {
        double sampled = 0;
        auto np = CGAL::parameters::number_of_points_on_faces(samples).random_seed(7);
        double sampled_s = median_time(
            [&] { sampled = PMP::approximate_Hausdorff_distance<CGAL::Sequential_tag>(ma, mb, np); },
            min_runs, min_time);
        std::printf(", \"samples\": %d, \"sampled\": %s, \"sampled_s\": %s", samples, num(sampled).c_str(),
                    num(sampled_s).c_str());
      }
      std::printf("}\n");
    } catch (const std::exception& e) {
      fail(std::string("CGAL error: ") + e.what());
    }
  }
  return 0;
}
