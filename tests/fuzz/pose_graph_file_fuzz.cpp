// libFuzzer target: the g2o / TORO pose-graph reader, and what a user does next with what it read:
// chi2, a few Levenberg-Marquardt iterations, the chordal start and the g2o writer. A malformed file
// must give a sextant::error; anything else escaping (or a sanitizer report) is a finding.
#include "fuzz_input_file.hpp"
#include "sextant/core/error.hpp"
#include "sextant/io/pose_graph_file.hpp"

namespace {

template <class Poses>
void exercise(sextant::PoseGraph<Poses>& graph, const std::string& written) {
  (void)graph.chi2();
  if (graph.num_edges() > 500) return;  // keep each input fast
  try {
    sextant::PoseGraph<Poses> chordal = graph;
    chordal.initialize_by_chordal_relaxation();
  } catch (const sextant::error&) {
  }
  sextant::PoseGraphOptions options;
  options.max_iterations = 3;
  try {
    graph.optimize(options);
  } catch (const sextant::error&) {
  }
  sextant::io::write_g2o(written, graph);
  (void)sextant::io::read_pose_graph(written);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static sextant::fuzz::InputFile file(".g2o");
  const std::string& path = file.write(data, size);
  const std::string written = path + ".written.g2o";
  try {
    auto graph = sextant::io::read_pose_graph(path);
    if (graph.dimension == 2) exercise(graph.planar, written);
    else exercise(graph.spatial, written);
  } catch (const sextant::error&) {
  }
  std::remove(written.c_str());
  return 0;
}
