#ifndef CLOTHWIND_SENSORS_FRAME_SOURCE_FACTORY_H_
#define CLOTHWIND_SENSORS_FRAME_SOURCE_FACTORY_H_

#include <memory>
#include <string>

#include "sensors/frame_source.h"

namespace clothwind {
namespace sensors {

// Builds the FrameSource the options name: "v4l2" (V4l2Camera on the real system calls),
// "video" (VideoFileSource) or "folder" (ImageFolderSource). Does not open it.
// Inputs:
//   options  what to build (source, path, format, size, rate, controls, loop)
//   clock    clocks (not owned; must outlive the source)
//   log      where the source reports negotiation results and failures (may be empty)
// Outputs:
//   error  when nullptr is returned: which option is wrong and what was expected
// Returns the source, or nullptr.
std::unique_ptr<FrameSource> MakeFrameSource(const FrameSourceOptions& options, Clock* clock,
                                             LogFn log, std::string* error);

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_FRAME_SOURCE_FACTORY_H_
