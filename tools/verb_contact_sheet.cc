// clothwind contact-sheet DIR: a grid of a dataset's middle frames labelled with their wind speed
// (any dataset in the docs/dataset.md format: simulated or recorded), to check it at a glance.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "data/contact_sheet.h"
#include "data/dataset_index.h"
#include "dataset_outputs.h"
#include "output_paths.h"
#include "progress_bar.h"
#include "render/sensor_model.h"
#include "verb_registry.h"
#include "usage_error.h"

namespace clothwind::tools {
namespace {

struct ContactSheetArgs {
  std::string dir;
  std::string out;  // "" = DIR/contact_sheet.png
  data::ContactSheetOptions options;
};

int Run(const ContactSheetArgs& a) {
  // The sheet is written as PNG or JPEG by its name's extension (any case): another failed only
  // after every tile was read, naming WriteFrameAtomic rather than --out.
  if (!a.out.empty() && !render::IsFrameFileName(a.out))
    throw UsageError("--out " + a.out + ": expected a file name ending in .png, .jpg or .jpeg");
  const nlohmann::json index = data::ReadIndex(a.dir);
  if (index.is_null()) throw std::runtime_error(a.dir + "/index.json not found: not a dataset folder");
  const std::string out =
      a.out.empty() ? (std::filesystem::path(a.dir) / "contact_sheet.png").string() : a.out;
  // Not over the dataset: `--out DIR/<clip>/003.jpg` replaced a clip's frame with the sheet.
  const std::filesystem::path dir(a.dir);
  RefuseOutputOverInput("--out", out, {dir / "index.json"});
  // Nor below a clip's folder: its missing folders are made now, and a sheet in a clip's subfolder
  // was written there (the test above compared the sheet's own folder alone).
  RefuseOutputInsideExamples("--out", out, dir, index);
  RefuseUnwritableOutput("--out", out);
  // The sheet is held whole in memory (3 bytes a pixel): 10000 tiles of 1024 px were 31 GB.
  const double sheet_bytes = static_cast<double>(a.options.max_tiles) * a.options.tile * a.options.tile * 3;
  if (sheet_bytes > 4.0 * (1ull << 30))
    throw UsageError("--tiles x --tile-size^2 x 3 bytes (the sheet, held in memory) must be at most 4 GiB, "
                                "got " + Num(sheet_bytes / (1ull << 30)) + " GiB");
  ProgressBar::Options b;
  b.label = "contact-sheet";
  b.unit = "tiles";
  ProgressBar bar(b);
  // Made before the tiles are read, and taken away again if no sheet is written (no clips, or a
  // frame that cannot be read): an empty folder was left behind.
  MadeFolders made = MakeFoldersFor("--out", out);
  const bool written =
      data::WriteContactSheet(a.dir, index, out, a.options, [&](int done, int total) { bar.Update(done, total); });
  bar.Finish();
  if (written) made.Keep();
  if (!written) {
    std::fprintf(stderr, "contact-sheet: %s has no clips\n", a.dir.c_str());
    return 1;
  }
  std::printf("contact-sheet: %s (%zu clips in the index, up to %d shown)\n", out.c_str(), index["clips"].size(),
              a.options.max_tiles);
  return 0;
}

const VerbRegistrar kRegistrar{"contact-sheet", [](CLI::App& app) -> std::function<int()> {
  auto a = std::make_shared<ContactSheetArgs>();
  auto* sub = app.add_subcommand("contact-sheet", "grid of a dataset's middle frames with their wind speeds (PNG)");
  sub->add_option("dir", a->dir, "dataset folder (with index.json)")->required();
  sub->add_option("--out", a->out, "sheet to write, .png, .jpg or .jpeg (default: DIR/contact_sheet.png)");
  sub->add_option("--tiles", a->options.max_tiles, "examples shown at most")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  sub->add_option("--tile-size", a->options.tile, "tile size [px]")->check(CLI::Range(32, 1024))->capture_default_str();
  return [a] { return Run(*a); };
}};

}  // namespace
}  // namespace clothwind::tools
