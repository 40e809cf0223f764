// sextant-globe-stereo: the thesis's image-to-map pipeline (issue 12): the globe rendered as stereo
// images (--dataset globe-stereo) or a user's rectified stereo sequence (--dataset stereo:<dir>)
// through the OpenCV front-end and the back-ends. It takes sextant-run's options (sextant-run hands
// these data sets over to it); see docs/runner.md.
#include "globe_stereo_runs.hpp"
#include "runner_cli.hpp"

int main(int argc, char** argv) {
  using namespace sextant::runner;
  return runner_main(argc, argv, "sextant-globe-stereo",
                     "sextant-globe-stereo: stereo images through the OpenCV front-end and every back-end",
                     [](CliOptions& options) {
                       if (options.datasets.empty()) options.datasets = {"globe-stereo"};
                       for (const auto& dataset : options.datasets)
                         if (!is_stereo_image_dataset(dataset))
                           throw sextant::invalid_input_error("--dataset " + dataset +
                                                              ": sextant-globe-stereo runs globe-stereo and stereo:<dir> (sextant-run runs the rest)");
                       const RunnerConfig config = load_runner_config(options);
                       const auto kinds = parse_backends(options.backends);
                       std::vector<TableRow> rows;
                       for (const auto& dataset : options.datasets) {
                         auto part = dataset == "globe-stereo"
                                         ? run_globe_stereo(options.output, options.save_images, kinds, config)
                                         : run_stereo_directory(options.output, dataset.substr(7), config);
                         rows.insert(rows.end(), part.begin(), part.end());
                       }
                       finish_run(options, rows);
                       return 0;
                     });
}
