#ifndef CLOTHWIND_SENSORS_DATASET_WRITER_H_
#define CLOTHWIND_SENSORS_DATASET_WRITER_H_

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sensors/clip_pipeline.h"

namespace clothwind::sensors {

// Where a recorded clip came from (written into its label.json).
struct ClipSourceInfo {
  std::string frame_id;     // camera optical frame
  std::string description;  // e.g. "clip_buffer_node /camera/image_raw"
  // Optional camera_info summary (width, height, frame_id, distortion_model, D, K); null when unknown.
  nlohmann::json camera;
  std::string split = "test";  // dataset split (docs/dataset.md); real clips evaluate, as FlagReal
  std::string wind_frame_id;  // frame of the label's mean direction (WindDirectionFrameGate)
};

// Folder name of a recorded clip: "clip-<UTC yyyymmdd-hhmmss.mmm of its first frame>", so names
// sort by time and a clip made again from the same frames gets the same name (and replaces the
// old one): replaying a session twice, or `rosbag play -l` into a running clip buffer. Clips start
// on the 25 Hz grid of their frames, 40 ms apart, so no two of one session share a millisecond.
// (A replay whose grid starts elsewhere, having lost the first frame, names its clips anew.) (Until stop 74 the clip's sequence number followed, which a loop
// or a lost frame shifts: each pass recorded every clip again under new names, and datasets
// counted them once a pass.)
std::string ClipFolderName(double first_stamp);

// DatasetWriter::Write's clip is recorded (in place, and in the index the writer holds) but what
// followed failed: the message says what (an index rewrite, the replaced copy's removal, the
// folder's sync). Not a failed write: counting it as one called a clip on disk not recorded.
class ClipRecordedWithAProblem : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Whether `dir` is a mount point: on another device than its parent folder ("/" is not; a
// trailing separator names the same folder). A recording folder that was one is reopened after
// a loss only once a disk is mounted there again (its bare mount point is not the disk).
// Inputs: dir  a folder path. Returns false when either cannot be stat'ed.
bool IsMountPoint(const std::string& dir);

// label.json of a recorded clip (format "clothwind-clip", version 1; see docs/clips.md).
nlohmann::json ClipLabelJson(const LabelledClip& clip, const ClipSourceInfo& source, const std::string& name);

// Records clips as a FlagReal-style dataset: <root>/<name>/000.jpg ... NNN.jpg + label.json, one
// folder per clip, plus <root>/index.json listing every clip. Each clip folder is written under a
// hidden temporary name and renamed into place, and the index is rewritten to a temporary file
// and renamed, so a reader (or a crash) never sees a half-written clip or index; every file is
// fsync'ed before the rename that publishes it and the folder after it, so a power cut leaves
// the old version or the new one, not an empty file. Opening an existing dataset appends to its
// index and clears what a writer that died left behind (its temporaries; a clip it was
// replacing is put back).
class DatasetWriter {
 public:
  // Inputs:
  //   root          dataset folder (created if missing; its parent must exist: a disk not
  //                 mounted yet is an error, not a folder made on the root filesystem that the
  //                 disk later hides)
  //   jpeg_quality  1..100 (95)
  //   index_interval  least seconds between rewrites of index.json (0: after every clip). Why:
  //                 the index is rewritten whole (~270 bytes a clip), so after a day at one clip
  //                 every 1.2 s each rewrite is ~19 MB, fsync'ed, and rewriting it for every clip
  //                 writes more than the clips' JPEGs by far. Clips written since the last
  //                 rewrite are in place but not listed (unlisted()): FlushIndex, the destructor
  //                 or the next writer to open the folder (which lists clips in place) lists them.
  //   now           the steady clock the interval is measured on (empty: steady_clock::now; tests
  //                 give a clock that starts near 0, as the steady clock does on a machine just booted)
  // Holds an exclusive lock on <root>/.lock while it lives: a second writer (another node, a
  // replay into the folder being recorded) is refused, since each rewrites the whole index.
  // Clip folders that a writer which died had renamed into place but not yet listed are added
  // to the index (reindexed()).
  // Throws std::runtime_error when the folder cannot be created or locked or its index.json is
  // not valid (the message names the file and what was expected); an index that cannot be read
  // is never overwritten.
  using SteadyNow = std::function<std::chrono::steady_clock::time_point()>;
  explicit DatasetWriter(const std::string& root, int jpeg_quality = 95, double index_interval = 0.0,
                         SteadyNow now = {});
  // Lists unlisted clips (FlushIndex); a failure is swallowed: the clips are in place, and the
  // next writer to open the folder lists them.
  ~DatasetWriter();
  DatasetWriter(const DatasetWriter&) = delete;
  DatasetWriter& operator=(const DatasetWriter&) = delete;

  // Writes one clip; returns the path of its folder. Refused when the folder is no longer the one
  // opened (a disk mounted over it, the folder moved): its index would replace the other's. A folder of the same name is replaced (the
  // same session replayed again; if that fails the old folder stays). Throws std::runtime_error
  // naming the file that failed; nothing half-written is left behind. When the clip is in place
  // but what follows failed (the index update, removing the copy it replaced, syncing the folder)
  // it throws ClipRecordedWithAProblem saying what: the clip is recorded, in the index held here,
  // and the next index written lists it.
  // index.json is rewritten unless the last rewrite was less than index_interval ago and the clip
  // is new (a clip replaced is listed at once: the next writer to open the folder would list a
  // missing clip, but not correct a stale entry).
  std::string Write(const LabelledClip& clip, const ClipSourceInfo& source);

  // Rewrites index.json if any clip is unlisted; returns whether it did. Throws
  // std::runtime_error naming the file when the rewrite fails (the clips stay in place, and
  // stay counted in unlisted()).
  bool FlushIndex();

  // Clips in the index held here (those on disk plus the unlisted ones).
  size_t size() const { return index_["clips"].size(); }
  // Clips recorded (or replaced) since index.json on disk was last rewritten.
  size_t unlisted() const { return unlisted_; }
  double index_interval() const { return index_interval_; }
  const std::string& root() const { return root_; }
  // Temporaries of a writer that died, cleared when this one opened the folder.
  size_t recovered() const { return recovered_; }
  // Clip folders found in place but missing from the index when this one opened it (a writer
  // that died between a clip's rename and its index update), added to the index.
  size_t reindexed() const { return reindexed_; }

 private:
  void WriteIndex();
  size_t RecoverLeftovers();
  size_t ReindexUnlisted();
  // Throws unless root_ is still the folder opened (device and inode).
  void CheckSameFolder() const;

 public:
  // Why the folder is no longer the one opened ("" while it is): gone, or another in its place
  // (a disk replugged and mounted again). Safe from any thread (reads what the constructor set).
  std::string FolderLost() const;

 private:

  std::string root_;
  int jpeg_quality_;
  nlohmann::json index_;
  size_t recovered_ = 0, reindexed_ = 0;
  double index_interval_ = 0.0;
  size_t unlisted_ = 0;
  SteadyNow now_;
  std::optional<std::chrono::steady_clock::time_point> last_index_write_;  // none: never written
  // The held <root>/.lock: a member that closes it, so a constructor that throws after taking it
  // releases it too (a destructor of the writer would not run then).
  struct LockFile {
    int fd = -1;
    ~LockFile();
  } lock_;
  unsigned long long device_ = 0, inode_ = 0;  // of root_ when opened
};

// Writes `text` to `path` through a temporary file in the same folder, fsync and a rename (then
// fsyncs the folder). Throws std::runtime_error naming the path when it fails; the temporary
// file is removed then.
void WriteFileAtomically(const std::string& path, const std::string& text);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_DATASET_WRITER_H_
