// The calibration file behind camera_node's ~camera_info_url, checked before camera_info_manager
// reads it. camera_info_manager hands the file to camera_calibration_parsers, which ends the
// process on two kinds of file instead of failing the load: a folder (std::ios_base::failure "Is a
// directory" from the stream, uncaught) and a YAML matrix of another shape than CameraInfo's
// (an assert on camera_matrix, rectification_matrix or projection_matrix rows/cols). A data
// list longer or shorter than rows x cols is read without a word (the extra values ignored, D
// cut short) or half read. A camera that aborts at start over its calibration takes the images
// down with it; one that publishes without calibration and says why keeps the clips coming.
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_CAMERA_CALIBRATION_FILE_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_CAMERA_CALIBRATION_FILE_H_

#include <functional>
#include <string>

#include <sensor_msgs/CameraInfo.h>

namespace clothwind::ros_bridge {

// camera_info_manager's URL when ~camera_info_url is empty.
inline constexpr char kDefaultCameraInfoUrl[] = "file://${ROS_HOME}/camera_info/${NAME}.yaml";

// The local file a calibration URL names, as camera_info_manager reads it.
// Inputs:
//   resolved_url  the URL with ${NAME} and ${ROS_HOME} already substituted
//                 (CameraInfoManager::resolveURL); an empty URL is camera_info_manager's default,
//                 to be resolved the same way first
//   package_path  a package's folder by name ("" when there is none: ros::package::getPath)
// Returns the path of a file:/// or package:// URL (schemes in any case, as camera_info_manager
// takes them); "" for other URLs (camera_info_manager refuses them itself, without harm).
std::string CalibrationFilePath(const std::string& resolved_url,
                                const std::function<std::string(const std::string&)>& package_path);

// Whether the file at `path` may be given to camera_calibration_parsers.
// Returns "" when it may: it does not exist (camera_info_manager reports that itself, and
// set_camera_info creates it), or it is a regular file that is not YAML (.ini), or YAML whose
// calibration matrices are whole; else why not, naming the file and what is wrong: not a regular
// file, unreadable, not a YAML mapping, a matrix without rows/cols/data, rows or cols other than
// CameraInfo's (K and R 3x3, P 3x4; D any), rows x cols other than the length of data, or data
// that are not numbers. A matrix left out is not judged (the parser fails on that harmlessly).
std::string CheckCalibrationFile(const std::string& path);

// A calibration as the text of the file at `path`, in the format its extension names (as
// camera_info_manager chose it: .yaml or .yml YAML, .ini INI).
// Inputs: path  the file it is for; camera_name  its camera_name; info  the calibration.
// Returns the text. Throws std::runtime_error naming the file for another extension, or when
// camera_calibration_parsers cannot write it.
std::string CalibrationFileText(const std::string& path, const std::string& camera_name,
                                const sensor_msgs::CameraInfo& info);

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_CAMERA_CALIBRATION_FILE_H_
