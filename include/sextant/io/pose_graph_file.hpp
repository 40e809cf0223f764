#pragma once
/// \file Pose graphs in g2o and TORO/MRPT text files, read into a PoseGraph and written as either.
///   g2o 2D: VERTEX_SE2 id x y th | EDGE_SE2 i j dx dy dth I11 I12 I13 I22 I23 I33 |
///           VERTEX_XY id x y | EDGE_SE2_XY i l x y I11 I12 I22 | EDGE_PRIOR_SE2 i x y th + 6 | FIX id...
///   g2o 3D: VERTEX_SE3:QUAT id x y z qx qy qz qw | EDGE_SE3:QUAT i j x y z qx qy qz qw + 21
///           (upper triangle, row by row) | VERTEX_TRACKXYZ id x y z |
///           EDGE_SE3_TRACKXYZ i l p x y z + 6 (12 values) | PARAMS_SE3OFFSET p x y z qx qy qz qw |
///           EDGE_SE3_PRIOR i p x y z qx qy qz qw + 21 | FIX id...
///   TORO:   VERTEX2 id x y th | EDGE2 i j dx dy dth I11 I12 I22 I33 I13 I23 |
///           VERTEX3 id x y z roll pitch yaw | EDGE3 i j x y z roll pitch yaw + 21
/// A file with edges but no vertex lines starts from a spanning tree of its odometry
/// (PoseGraph::initialize_by_spanning_tree). Anything the reader cannot use is a parse_error naming
/// file:line (tests/io/pose_graph_file_test.cpp, tests/fuzz/pose_graph_file_fuzz.cpp).

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "sextant/backends/pose_graph.hpp"
#include "sextant/io/input_file.hpp"
#include "sextant/io/text_record.hpp"

namespace sextant::io {

/// What a pose-graph file held.
struct PoseGraphFile {
  int dimension = 0;         ///< 2 (SE(2)) or 3 (SE(3))
  std::string format;        ///< "g2o" or "TORO"
  bool spanning_tree_start = false;  ///< no vertex lines: the poses start from a spanning tree
  PoseGraph<PlanarPoses> planar;     ///< when dimension == 2
  PoseGraph<SpatialPoses> spatial;   ///< when dimension == 3
};

namespace detail {

/// A symmetric matrix from its upper triangle, row by row, starting at values[first].
template <int N>
Eigen::Matrix<double, N, N> upper_triangle_at(const std::vector<double>& values, std::size_t first) {
  Eigen::Matrix<double, N, N> out;
  for (int r = 0; r < N; ++r)
    for (int c = r; c < N; ++c) out(r, c) = out(c, r) = values[first++];
  return out;
}

/// The unit quaternion (qx qy qz qw at values[first]) as a rotation matrix; parse_error when it is
/// far from unit length (it is normalized when within 1e-3 of it, as written files round it).
inline Eigen::Matrix3d rotation_from_quaternion(const TextRecord& record, std::size_t first) {
  const Eigen::Quaterniond q(record.values[first + 3], record.values[first], record.values[first + 1],
                             record.values[first + 2]);
  if (!(std::abs(q.norm() - 1.0) <= 1e-3))
    throw parse_error(record.where + ": quaternion of norm " + std::to_string(q.norm()) + ", not a rotation");
  return q.normalized().toRotationMatrix();
}

inline Eigen::Matrix4d pose3_from_quaternion(const TextRecord& record, std::size_t first) {
  return se3::make(rotation_from_quaternion(record, first + 3),
                   Eigen::Vector3d(record.values[first], record.values[first + 1], record.values[first + 2]));
}

/// TORO/MRPT 3D poses: x y z roll pitch yaw with R = Rz(yaw) Ry(pitch) Rx(roll).
inline Eigen::Matrix4d pose3_from_euler(const TextRecord& record, std::size_t first) {
  const auto& v = record.values;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(v[first + 5], Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(v[first + 4], Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(v[first + 3], Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  return se3::make(R, Eigen::Vector3d(v[first], v[first + 1], v[first + 2]));
}

/// TORO's 3D information is over (x y z roll pitch yaw) increments; the g2o error's rotation part
/// is the quaternion's vector, half the small angles: Omega_q = J^T Omega J with J = diag(I, 2 I)
/// (exact for small errors; scales by 2 and 1/2 are exact in floating point, so a file written and
/// read back keeps every bit). `inverse` goes the other way, for writing TORO.
inline Eigen::Matrix<double, 6, 6> toro_information_3d(const Eigen::Matrix<double, 6, 6>& I, bool inverse = false) {
  Eigen::Matrix<double, 6, 1> j;
  j << 1, 1, 1, 2, 2, 2;
  if (inverse) j.tail<3>().setConstant(0.5);
  return j.asDiagonal() * I * j.asDiagonal();
}

/// (roll, pitch, yaw) of R = Rz(yaw) Ry(pitch) Rx(roll), TORO's and MRPT's convention.
inline Eigen::Vector3d roll_pitch_yaw(const Eigen::Matrix3d& R) {
  return {std::atan2(R(2, 1), R(2, 2)), std::atan2(-R(2, 0), std::hypot(R(0, 0), R(1, 0))), std::atan2(R(1, 0), R(0, 0))};
}

/// The records of a file, its dimension and format, and which vertices its edges name.
class PoseGraphFileBuilder {
 public:
  explicit PoseGraphFileBuilder(std::string path) : path_(std::move(path)) {}

  void note(const TextRecord& record) {
    const auto kind = kind_of(record);
    if (kind.dimension != 0) {
      if (out_.dimension != 0 && out_.dimension != kind.dimension)
        throw parse_error(record.where + ": " + record.tag + " is a " + std::to_string(kind.dimension) +
                          "D record in a file whose first records are " + std::to_string(out_.dimension) + "D");
      out_.dimension = kind.dimension;
    }
    if (kind.format) {
      if (!out_.format.empty() && out_.format != kind.format)
        throw parse_error(record.where + ": " + record.tag + " is a " + kind.format + " record in a " + out_.format + " file");
      out_.format = kind.format;
    }
    record.require_fields(kind.fields == 0 ? std::max<std::size_t>(record.values.size(), 1) : kind.fields);
    (kind.vertex ? vertices_ : kind.fix ? fixes_ : kind.parameter ? parameters_ : edges_).push_back(record);
  }

  PoseGraphFile build() {
    if (out_.dimension == 0) throw parse_error(path_ + ": no vertex or edge records (not a g2o or TORO file)");
    if (out_.dimension == 2) build_graph(out_.planar);
    else build_graph(out_.spatial);
    return std::move(out_);
  }

 private:
  struct Kind {
    int dimension = 0;
    const char* format = nullptr;
    std::size_t fields = 0;  ///< 0: one or more (FIX)
    bool vertex = false, fix = false, parameter = false;
  };
  static Kind kind_of(const TextRecord& r) {
    static const std::map<std::string, Kind> kinds = {
        {"VERTEX_SE2", {2, "g2o", 4, true}},        {"EDGE_SE2", {2, "g2o", 11}},
        {"VERTEX_XY", {2, "g2o", 3, true}},         {"EDGE_SE2_XY", {2, "g2o", 7}},
        {"EDGE_PRIOR_SE2", {2, "g2o", 10}},         {"VERTEX_SE3:QUAT", {3, "g2o", 8, true}},
        {"EDGE_SE3:QUAT", {3, "g2o", 30}},          {"VERTEX_TRACKXYZ", {3, "g2o", 4, true}},
        {"EDGE_SE3_TRACKXYZ", {3, "g2o", 12}},      {"EDGE_SE3_PRIOR", {3, "g2o", 30}},
        {"PARAMS_SE3OFFSET", {3, "g2o", 8, false, false, true}},
        {"FIX", {0, nullptr, 0, false, true}},      {"VERTEX2", {2, "TORO", 4, true}},
        {"EDGE2", {2, "TORO", 11}},                 {"VERTEX3", {3, "TORO", 7, true}},
        {"EDGE3", {3, "TORO", 29}},
    };
    const auto it = kinds.find(r.tag);
    if (it == kinds.end()) throw parse_error(r.where + ": unknown record '" + printable_excerpt(r.tag) + "'");
    return it->second;
  }

  static VertexId id(const TextRecord& r, std::size_t index) {
    return static_cast<VertexId>(r.identifier(index, "vertex id"));
  }

  template <class Poses>
  void build_graph(PoseGraph<Poses>& graph) {
    for (const auto& r : vertices_) at(r, [&] { add_vertex(graph, r); });
    for (const auto& r : parameters_) at(r, [&] { add_parameter(r); });
    out_.spanning_tree_start = vertices_.empty();
    if (out_.spanning_tree_start) add_vertices_edges_name(graph);
    for (const auto& r : edges_) at(r, [&] { add_edge(graph, r); });
    for (const auto& r : fixes_)
      for (std::size_t k = 0; k < r.values.size(); ++k) at(r, [&] { graph.fix(id(r, k)); });
    if (out_.spanning_tree_start) graph.initialize_by_spanning_tree();
  }

  /// Runs `step`, naming the record in the message of what it throws.
  template <class Step>
  static void at(const TextRecord& r, Step step) {
    try {
      step();
    } catch (const parse_error&) {
      throw;
    } catch (const error& e) {
      throw parse_error(r.where + ": " + e.what());
    }
  }

  template <class Poses>
  void add_vertex(PoseGraph<Poses>& graph, const TextRecord& r) {
    const auto& v = r.values;
    if (r.tag == "VERTEX_SE2" || r.tag == "VERTEX2") {
      if constexpr (Poses::kDim == 3) graph.add_pose(id(r, 0), Eigen::Vector3d(v[1], v[2], wrap_angle(v[3])));
    } else if (r.tag == "VERTEX_XY" || r.tag == "VERTEX_TRACKXYZ") {
      graph.add_point(id(r, 0), Eigen::Map<const typename PoseGraph<Poses>::Point>(v.data() + 1));
    } else if constexpr (Poses::kDim == 6) {
      graph.add_pose(id(r, 0), r.tag == "VERTEX3" ? pose3_from_euler(r, 1) : pose3_from_quaternion(r, 1));
    }
  }

  void add_parameter(const TextRecord& r) {
    if (!offsets_.emplace(static_cast<long long>(r.identifier(0, "parameter id")), pose3_from_quaternion(r, 1)).second)
      throw parse_error(r.where + ": parameter " + std::to_string(r.values[0]) + " is defined twice");
  }
  Eigen::Matrix4d offset(const TextRecord& r, std::size_t index) const {
    const auto it = offsets_.find(static_cast<long long>(r.identifier(index, "parameter id")));
    if (it == offsets_.end())
      throw parse_error(r.where + ": parameter " + std::to_string(r.values[index]) + " is not defined (PARAMS_SE3OFFSET)");
    return it->second;
  }

  /// A file of edges only: its poses and points, in the order edges first name them.
  template <class Poses>
  void add_vertices_edges_name(PoseGraph<Poses>& graph) {
    for (const auto& r : edges_) {
      const bool to_point = r.tag == "EDGE_SE2_XY" || r.tag == "EDGE_SE3_TRACKXYZ";
      const bool unary = r.tag == "EDGE_PRIOR_SE2" || r.tag == "EDGE_SE3_PRIOR";
      if (!graph.has_vertex(id(r, 0))) graph.add_pose(id(r, 0), Poses::identity());
      if (unary || graph.has_vertex(id(r, 1))) continue;
      if (to_point) graph.add_point(id(r, 1), PoseGraph<Poses>::Point::Zero());
      else graph.add_pose(id(r, 1), Poses::identity());
    }
  }

  template <class Poses>
  void add_edge(PoseGraph<Poses>& graph, const TextRecord& r) {
    const auto& v = r.values;
    for (std::size_t k = 0; k < (r.tag == "EDGE_PRIOR_SE2" || r.tag == "EDGE_SE3_PRIOR" ? 1u : 2u); ++k)
      if (!graph.has_vertex(id(r, k)))
        throw parse_error(r.where + ": " + r.tag + " names vertex " + std::to_string(id(r, k)) +
                          ", which no vertex record defines");
    if constexpr (Poses::kDim == 3) {
      if (r.tag == "EDGE_SE2") {
        graph.add_between(id(r, 0), id(r, 1), Eigen::Vector3d(v[2], v[3], v[4]), upper_triangle_at<3>(v, 5));
      } else if (r.tag == "EDGE2") {  // TORO: I11 I12 I22 I33 I13 I23
        Eigen::Matrix3d I;
        I << v[5], v[6], v[9], v[6], v[7], v[10], v[9], v[10], v[8];
        graph.add_between(id(r, 0), id(r, 1), Eigen::Vector3d(v[2], v[3], v[4]), I);
      } else if (r.tag == "EDGE_SE2_XY") {
        graph.add_point_observation(id(r, 0), id(r, 1), Eigen::Vector2d(v[2], v[3]), upper_triangle_at<2>(v, 4));
      } else {  // EDGE_PRIOR_SE2
        graph.add_pose_prior(id(r, 0), Eigen::Vector3d(v[1], v[2], v[3]), upper_triangle_at<3>(v, 4));
      }
    } else {
      if (r.tag == "EDGE_SE3:QUAT") {
        graph.add_between(id(r, 0), id(r, 1), pose3_from_quaternion(r, 2), upper_triangle_at<6>(v, 9));
      } else if (r.tag == "EDGE3") {
        graph.add_between(id(r, 0), id(r, 1), pose3_from_euler(r, 2), toro_information_3d(upper_triangle_at<6>(v, 8)));
      } else if (r.tag == "EDGE_SE3_TRACKXYZ") {
        graph.add_point_observation(id(r, 0), id(r, 1), Eigen::Vector3d(v[3], v[4], v[5]), upper_triangle_at<3>(v, 6),
                                    offset(r, 2));
      } else {  // EDGE_SE3_PRIOR i p x y z q + 21
        if (!offset(r, 1).isIdentity(1e-12))
          throw parse_error(r.where + ": EDGE_SE3_PRIOR with a non-identity offset parameter is not supported");
        graph.add_pose_prior(id(r, 0), pose3_from_quaternion(r, 2), upper_triangle_at<6>(v, 9));
      }
    }
  }


  std::string path_;
  PoseGraphFile out_;
  std::vector<TextRecord> vertices_, edges_, fixes_, parameters_;
  std::map<long long, Eigen::Matrix4d> offsets_;
};

}  // namespace detail

/// Reads a g2o or TORO pose-graph file; throws parse_error naming file:line for an unknown record,
/// a wrong number of values, a value that is not a finite number, 2D and 3D or g2o and TORO records
/// mixed, a vertex defined twice, an edge naming a vertex no record defines (in a file with vertex
/// records), an information matrix that is not symmetric positive definite, or a quaternion that is
/// not of unit length.
inline PoseGraphFile read_pose_graph(const std::string& path) {
  std::ifstream in = open_input_file(path);
  detail::PoseGraphFileBuilder builder(path);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number)
    if (const auto record = detail::parse_text_record(line, path + ":" + std::to_string(number))) builder.note(*record);
  return builder.build();
}

namespace detail {

inline void write_numbers(std::FILE* out, const double* values, int count) {
  for (int k = 0; k < count; ++k) std::fprintf(out, " %.17g", values[k]);
}
template <int N>
void write_upper_triangle(std::FILE* out, const Eigen::Matrix<double, N, N>& M) {
  for (int r = 0; r < N; ++r)
    for (int c = r; c < N; ++c) std::fprintf(out, " %.17g", M(r, c));
}
/// x y z qx qy qz qw.
inline Eigen::Matrix<double, 7, 1> pose3_as_quaternion(const Eigen::Matrix4d& T) {
  const Eigen::Quaterniond q(se3::rotation(T));
  Eigen::Matrix<double, 7, 1> out;
  out << se3::translation(T), q.x(), q.y(), q.z(), q.w();
  return out;
}

}  // namespace detail

namespace detail {

/// x y th, or x y z qx qy qz qw.
template <class Poses>
void write_g2o_pose(std::FILE* out, const typename Poses::Pose& x) {
  if constexpr (Poses::kDim == 3) write_numbers(out, x.data(), 3);
  else write_numbers(out, pose3_as_quaternion(x).data(), 7);
}

/// The vertices in the order they were added.
template <class Poses>
void write_g2o_vertices(std::FILE* out, const PoseGraph<Poses>& graph) {
  constexpr bool planar = Poses::kDim == 3;
  for (const auto& v : graph.vertices()) {
    if (v.is_point) {
      std::fprintf(out, planar ? "VERTEX_XY %lld" : "VERTEX_TRACKXYZ %lld", static_cast<long long>(v.id));
      write_numbers(out, graph.points()[v.slot].data(), Poses::kPointDim);
    } else {
      std::fprintf(out, planar ? "VERTEX_SE2 %lld" : "VERTEX_SE3:QUAT %lld", static_cast<long long>(v.id));
      write_g2o_pose<Poses>(out, graph.poses()[v.slot]);
    }
    std::fprintf(out, "\n");
  }
}

/// Between edges, priors and point observations (3D: through PARAMS_SE3OFFSET ids `offset_id` gives).
template <class Poses, class OffsetId>
void write_g2o_edges(std::FILE* out, const PoseGraph<Poses>& graph, OffsetId offset_id) {
  constexpr bool planar = Poses::kDim == 3;
  for (const auto& e : graph.betweens()) {
    std::fprintf(out, "%s %lld %lld", planar ? "EDGE_SE2" : "EDGE_SE3:QUAT", static_cast<long long>(graph.pose_id(e.from)),
                 static_cast<long long>(graph.pose_id(e.to)));
    write_g2o_pose<Poses>(out, e.z);
    write_upper_triangle(out, e.information);
    std::fprintf(out, "\n");
  }
  for (const auto& p : graph.priors()) {
    if constexpr (planar) std::fprintf(out, "EDGE_PRIOR_SE2 %lld", static_cast<long long>(graph.pose_id(p.pose)));
    else std::fprintf(out, "EDGE_SE3_PRIOR %lld 0", static_cast<long long>(graph.pose_id(p.pose)));
    write_g2o_pose<Poses>(out, p.z);
    write_upper_triangle(out, p.information);
    std::fprintf(out, "\n");
  }
  for (const auto& o : graph.observations()) {
    std::fprintf(out, "%s %lld %lld", planar ? "EDGE_SE2_XY" : "EDGE_SE3_TRACKXYZ", static_cast<long long>(graph.pose_id(o.pose)),
                 static_cast<long long>(graph.point_id(o.point)));
    if constexpr (!planar) std::fprintf(out, " %zu", offset_id(o.offset));
    write_numbers(out, o.z.data(), Poses::kPointDim);
    write_upper_triangle(out, o.information);
    std::fprintf(out, "\n");
  }
}

}  // namespace detail

/// Writes the graph as a g2o file (17 significant digits: read back, every number is the same
/// double): the sensor offsets (3D, where an edge needs one), vertices in the order they were
/// added, edges, priors, observations and FIX. Throws parse_error when the file cannot be written.
template <class Poses>
void write_g2o(const std::string& path, const PoseGraph<Poses>& graph) {
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (!out) throw parse_error(path + ": cannot write file");
  std::vector<Eigen::Matrix4d> offsets;  // 3D: one PARAMS_SE3OFFSET per distinct offset
  auto offset_id = [&](const Eigen::Matrix4d& T) {
    for (std::size_t k = 0; k < offsets.size(); ++k)
      if (offsets[k] == T) return k;
    offsets.push_back(T);
    return offsets.size() - 1;
  };
  if constexpr (Poses::kDim == 6) {  // PARAMS_SE3OFFSET only where an edge needs one (MRPT's reader warns of them)
    if (!graph.observations().empty() || !graph.priors().empty()) offset_id(Eigen::Matrix4d::Identity());
    for (const auto& obs : graph.observations()) offset_id(obs.offset);
    for (std::size_t k = 0; k < offsets.size(); ++k) {
      std::fprintf(out, "PARAMS_SE3OFFSET %zu", k);
      detail::write_numbers(out, detail::pose3_as_quaternion(offsets[k]).data(), 7);
      std::fprintf(out, "\n");
    }
  }
  detail::write_g2o_vertices(out, graph);
  detail::write_g2o_edges(out, graph, offset_id);
  for (const auto& v : graph.vertices())
    if (v.fixed) std::fprintf(out, "FIX %lld\n", static_cast<long long>(v.id));
  const bool failed = std::ferror(out) != 0;
  if (std::fclose(out) != 0 || failed) throw parse_error(path + ": writing the file failed");
}

/// Writes the graph as a TORO file (VERTEX2 / EDGE2 with information I11 I12 I22 I33 I13 I23, or
/// VERTEX3 / EDGE3 with x y z roll pitch yaw and the information over them), as MRPT's `graph-slam`
/// reads it. TORO has no points or priors: a graph with them is refused (parse_error), as is a file
/// that cannot be written. Fixed vertices are not written (TORO has no FIX).
template <class Poses>
void write_toro(const std::string& path, const PoseGraph<Poses>& graph) {
  constexpr bool planar = Poses::kDim == 3;
  if (graph.num_points() > 0 || !graph.priors().empty())
    throw parse_error(path + ": TORO files hold poses and edges between them only (the graph has points or priors)");
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (!out) throw parse_error(path + ": cannot write file");
  auto write_pose = [&](const typename Poses::Pose& x) {
    if constexpr (planar) {
      detail::write_numbers(out, x.data(), 3);
    } else {
      const Eigen::Vector3d t = se3::translation(x), rpy = detail::roll_pitch_yaw(se3::rotation(x));
      detail::write_numbers(out, t.data(), 3);
      detail::write_numbers(out, rpy.data(), 3);
    }
  };
  for (const auto& v : graph.vertices()) {
    std::fprintf(out, "%s %lld", planar ? "VERTEX2" : "VERTEX3", static_cast<long long>(v.id));
    write_pose(graph.poses()[v.slot]);
    std::fprintf(out, "\n");
  }
  for (const auto& e : graph.betweens()) {
    std::fprintf(out, "%s %lld %lld", planar ? "EDGE2" : "EDGE3", static_cast<long long>(graph.pose_id(e.from)),
                 static_cast<long long>(graph.pose_id(e.to)));
    write_pose(e.z);
    if constexpr (planar) {
      const auto& I = e.information;
      const double toro_order[6] = {I(0, 0), I(0, 1), I(1, 1), I(2, 2), I(0, 2), I(1, 2)};
      detail::write_numbers(out, toro_order, 6);
    } else {
      detail::write_upper_triangle(out, detail::toro_information_3d(e.information, true));
    }
    std::fprintf(out, "\n");
  }
  const bool failed = std::ferror(out) != 0;
  if (std::fclose(out) != 0 || failed) throw parse_error(path + ": writing the file failed");
}

}  // namespace sextant::io
