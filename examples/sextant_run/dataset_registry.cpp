// The registry of the runner's data-set families and programs (dataset_registry.hpp), and the one
// main() every runner program shares.
#include "dataset_registry.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <unistd.h>

#include "mpi_world.hpp"
#include "runner_config.hpp"
#include "sextant/core/error.hpp"

namespace sextant::runner {
namespace {

bool is(const std::string& dataset, const char* name) { return dataset == name; }
bool starts_with(const std::string& dataset, const char* prefix) { return dataset.rfind(prefix, 0) == 0; }
bool has_extension(const std::string& dataset, const char* extension) {
  return std::filesystem::path(dataset).extension() == extension;
}

}  // namespace

const std::vector<DatasetFamily>& dataset_families() {
  static const std::vector<DatasetFamily> families = {
      {"ship", "ship", "sextant-run", [](const std::string& d) { return is(d, "ship"); },
       "the thesis's 2D beacon ship, a Monte Carlo over [ship] runs seeds", true},
      {"mrpt-demos", "mrpt-demos", "sextant-run", [](const std::string& d) { return is(d, "mrpt-demos"); },
       "MRPT's kf-slam demo rawlogs (Debian's mrpt-common)"},
      {"globe", "globe", "sextant-globe", [](const std::string& d) { return is(d, "globe"); },
       "the thesis's 12D camera around a simulated globe"},
      {"globe-stereo", "globe-stereo", "sextant-globe-stereo", [](const std::string& d) { return is(d, "globe-stereo"); },
       "the globe rendered as stereo images, through the OpenCV front-end"},
      {"stereo", "stereo:<dir>", "sextant-globe-stereo", [](const std::string& d) { return starts_with(d, "stereo:"); },
       "a rectified stereo sequence (left/, right/, calib.yaml) through the front-end"},
      {"stereo-vi", "stereo-vi", "sextant-vislam", [](const std::string& d) { return is(d, "stereo-vi"); },
       "visual-inertial SLAM on SE(3) on the simulated stereo car"},
      {"npz", "<file.npz>", "sextant-vislam", [](const std::string& d) { return has_extension(d, ".npz"); },
       "visual-inertial SLAM on a KITTI-derived stereo+IMU file"},
      {"mrclam", "mrclam:<dir>:<robot 1-5|all>", "sextant-run-mrclam",
       [](const std::string& d) { return starts_with(d, "mrclam:"); }, "UTIAS MRCLAM robots against Vicon"},
      {"isam", "<file.txt>", "sextant-run-isam", [](const std::string& d) { return has_extension(d, ".txt"); },
       "a planar data set in the iSAM/GTSAM text format"},
      {"pose-graph", "<file.g2o|file.graph>", "sextant-pose-graph",
       [](const std::string& d) { return has_extension(d, ".g2o") || has_extension(d, ".graph"); },
       "a 2D or 3D pose graph in g2o or TORO/MRPT format, optimized (written back as .g2o with --out)"},
      {"square", "square[:<seed>]", "sextant-run", [](const std::string& d) { return is(d, "square") || starts_with(d, "square:"); },
       "a robot with wheel odometry on a square loop among point landmarks (docs/runner.md's worked example)"},
      {"rawlog", "<file.rawlog>", "sextant-run", [](const std::string&) { return true; },
       "an MRPT rawlog with its ground truth beside it"},
  };
  return families;
}

const DatasetFamily& family_of(const std::string& dataset) {
  for (const auto& family : dataset_families())
    if (family.recognizes(dataset)) return family;
  throw invalid_input_error("--dataset " + dataset + ": no data-set family recognizes it");
}

const RunnerProgram& runner_program(const std::string& name) {
  static const std::vector<RunnerProgram> programs = {
      {"sextant-run", "sextant-run: SLAM back-ends on the simulated ship and on MRPT rawlogs, side by side",
       "the ship and rawlogs", {"ship", "mrpt-demos"}},
      {"sextant-globe", "sextant-globe: the thesis's 12D camera around a simulated globe, every back-end through the landmark pool",
       "only the globe", {"globe"}},
      {"sextant-globe-stereo", "sextant-globe-stereo: stereo images through the OpenCV front-end and every back-end",
       "globe-stereo and stereo:<dir>", {"globe-stereo"}},
      {"sextant-vislam",
       "sextant-vislam: visual-inertial SLAM on SE(3) on .npz stereo+IMU data or the simulated stereo car",
       "stereo-vi and .npz files", {"stereo-vi"}},
      {"sextant-run-mrclam", "sextant-run-mrclam: SLAM back-ends on the UTIAS MRCLAM robots against Vicon",
       "mrclam:<dir>:<robot 1-5|all>", {}},
      {"sextant-run-isam", "sextant-run-isam: SLAM back-ends on a planar iSAM/GTSAM text data set",
       ".txt files (iSAM/GTSAM planar text)", {}},
      {"sextant-pose-graph", "sextant-pose-graph: a pose graph from a g2o or TORO file, optimized",
       ".g2o and .graph files (pose graphs)", {}},
  };
  const auto it = std::find_if(programs.begin(), programs.end(), [&](const RunnerProgram& p) { return name == p.name; });
  if (it == programs.end()) throw invalid_input_error("no runner program is named " + name);
  return *it;
}

std::string dataset_help(const std::string& program) {
  std::string help;
  for (const auto& family : dataset_families()) help += std::string(help.empty() ? "" : " | ") + family.syntax;
  std::string defaults;
  for (const auto& d : runner_program(program).defaults) defaults += (defaults.empty() ? "" : ", ") + d;
  return help + " (repeatable; default: " + (defaults.empty() ? "none" : defaults) +
         "). Each family runs in one program; sextant-run hands the others' over";
}

namespace {

std::map<std::string, DatasetRun>& registered_runs() {
  static std::map<std::string, DatasetRun> runs;
  return runs;
}

/// The program whose families all of `datasets` are, or nullptr when they are this program's;
/// throws when a family of another program is mixed with others.
const char* handed_over_to(const std::vector<std::string>& datasets, const char* program) {
  for (const auto& dataset : datasets) {
    const auto& family = family_of(dataset);
    if (std::strcmp(family.program, program) == 0) continue;
    const auto other = std::count_if(datasets.begin(), datasets.end(),
                                     [&](const std::string& d) { return std::strcmp(family_of(d).program, family.program) != 0; });
    if (other > 0)
      throw invalid_input_error(std::string("--dataset ") + family.syntax + ": runs alone (in the program " +
                                family.program + "); give the other data sets in a second call");
    return family.program;
  }
  return nullptr;
}

/// Replaces this process by `program` (next to it) with the same arguments.
int hand_over_to(const char* program, char** argv) {
  const auto path = std::filesystem::canonical("/proc/self/exe").parent_path() / program;
  std::fflush(stdout);
  ::execv(path.c_str(), argv);
  std::fprintf(stderr, "sextant-run: cannot start %s (%s): build it with cmake --build <build> --target %s, or "
               "run ./run.sh main with the same --dataset\n", path.c_str(), std::strerror(errno), program);
  return 1;
}

/// Whether this process runs `dataset`: a shard (--shard or an MPI rank) runs its share of the seeded
/// data sets; the others run in one process only (MPI's rank 0), and --shard refuses them when named.
bool runs_here(const CliOptions& options, const std::string& dataset, bool named) {
  if (family_of(dataset).seeded || options.study.mode == StudyPart::Mode::whole) return true;
  if (options.study.mode == StudyPart::Mode::mpi) return options.study.prints();
  if (named)
    throw invalid_input_error("--shard: --dataset " + dataset + " is one run, not a Monte Carlo over seeds (only " +
                              "seeded data sets such as ship are sharded)");
  return false;
}

/// The data sets of this program (sextant-run hands the others over before): each by its family's run.
int run_own_datasets(CliOptions& options, const RunnerProgram& program, bool named) {
  for (const auto& dataset : options.datasets)
    if (std::strcmp(family_of(dataset).program, program.name) != 0)
      throw invalid_input_error("--dataset " + dataset + ": " + program.name + " runs " + program.runs +
                                " (sextant-run runs the rest)");
  const RunnerConfig config = load_runner_config(options);
  const auto kinds = parse_backends(options.backends);
  std::vector<TableRow> rows;
  for (const auto& dataset : options.datasets) {
    if (!runs_here(options, dataset, named)) continue;
    auto part = registered_run(family_of(dataset).key)(options, dataset, kinds, config);
    rows.insert(rows.end(), part.begin(), part.end());
  }
  if (options.study.prints() && !rows.empty()) finish_run(options, rows);  // pose graphs print their own table
  return 0;
}

/// Runs this program's data sets as this process's part of their studies (monte_carlo_study.hpp):
/// joins MPI when mpirun started it and leaves it however the run ends; a rank that fails says so and
/// ends all of them (the others would wait for its records).
int run_as_study_part(int argc, char** argv, CliOptions& options, const RunnerProgram& program, bool named) {
  try {
    options.study = study_part(program.name, options.shard, options.output.out, argc, argv, options.config);
    const int status = run_own_datasets(options, program, named);
    mpi::leave(status != 0);
    return status;
  } catch (const std::exception& e) {
    if (options.study.mode != StudyPart::Mode::mpi) {
      mpi::leave(false);
      throw;
    }
    std::fprintf(stderr, "%s (rank %d of %d): %s\n", program.name, options.study.shard.index,
                 options.study.shard.count, e.what());
    mpi::leave(true);
    return 1;
  }
}

}  // namespace

RegisterDatasetRun::RegisterDatasetRun(const char* key, DatasetRun run) { registered_runs()[key] = run; }

DatasetRun registered_run(const std::string& key) {
  const auto it = registered_runs().find(key);
  if (it == registered_runs().end())
    throw invalid_input_error("the data-set family " + key + " has no run in this program");
  return it->second;
}

int program_main(int argc, char** argv, const char* name) {
  const RunnerProgram& program = runner_program(name);
  return runner_main(argc, argv, program.name, program.description, [&](CliOptions& options) {
    if (!options.merge.empty()) {
      if (!options.datasets.empty() || !options.shard.empty())
        throw invalid_input_error("--merge prints a study from its records: no --dataset or --shard with it");
      finish_run(options, merged_rows(program.name, options.merge));
      return 0;
    }
    const bool named = !options.datasets.empty();
    if (!named) options.datasets = program.defaults;
    if (std::strcmp(name, "sextant-run") == 0)
      if (const char* other = handed_over_to(options.datasets, name)) return hand_over_to(other, argv);
    return run_as_study_part(argc, argv, options, program, named);
  });
}

}  // namespace sextant::runner
