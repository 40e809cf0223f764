// sextant-globe-stereo: the thesis's image-to-map pipeline (issue 12): the globe rendered as stereo
// images (--dataset globe-stereo) or a user's rectified stereo sequence (--dataset stereo:<dir>)
// through the OpenCV front-end and the back-ends. It takes sextant-run's options (sextant-run hands
// these data sets over to it); see docs/runner.md.
#include "globe_stereo_runs.hpp"
#include "runner_cli.hpp"

using namespace sextant::runner;

int main(int argc, char** argv) {
  return family_main(
      argc, argv, "sextant-globe-stereo",
      "sextant-globe-stereo: stereo images through the OpenCV front-end and every back-end",
      is_stereo_image_dataset, "globe-stereo and stereo:<dir>",
      [](const CliOptions& options, const std::string& dataset, const std::vector<BackendKind>& kinds,
         const RunnerConfig& config) {
        if (dataset == "globe-stereo") return run_globe_stereo(options.output, options.save_images, kinds, config);
        return run_stereo_directory(options.output, dataset.substr(7), config);
      },
      {"globe-stereo"});
}
