// Private node parameters read strictly. roscpp's NodeHandle::param returns the default when a
// parameter is set with another XmlRpc type than the one asked for, without a word: roslaunch
// turned `record_dir:=20261206` into an int, param<std::string> left record_dir empty and no clip
// was recorded; a YAML `rate: "5"` left camera_node at 30 Hz. Here a parameter that is set with a
// value its node cannot take is a ParamError naming "~name", the type found and the type
// expected; nodes end on it with a FATAL (it is startup configuration, not a runtime condition).
//
// What each type takes (see ParamValue below for why):
//   bool                 true / false, or the ints 1 / 0 (`_loop:=1` on a command line is an int)
//   int                  an int only
//   double               a double or an int (`rate: 5` in YAML, `value="60"` in a launch file)
//   std::string          a string, or an int as its decimal text (record_dir:=20261206)
//   std::vector<double>  a list of ints and doubles
//
// StrictParams also remembers which parameters a node asked for, so the private parameters set
// and never read (a misspelt key, a key of another node's config) are named once at start.
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_STRICT_PARAM_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_STRICT_PARAM_H_

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcValue.h>

namespace clothwind::ros_bridge {

// A parameter set with a value its node cannot take. The message names the parameter ("~rate").
class ParamError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// The type of `v` as messages name it: "bool", "int", "double", "string", "list", "dictionary"...
std::string XmlRpcTypeName(const XmlRpc::XmlRpcValue& v);

// Converts one parameter value (no ROS master needed: the part unit tests reach).
// Inputs:
//   v     the value as the parameter server holds it
//   name  the parameter as messages name it ("~rate")
//   note  when not null, set to a line to log when the value was converted with a possible loss
//         (an int read as text), else cleared
// Returns the value as T. Throws ParamError naming `name`, the type found and the type expected.
// Defined for bool, int, double, std::string and std::vector<double>:
//   - int refuses a double: 2.5 buffers means nothing, and 640.0 px is a slip worth a word.
//   - double takes an int: YAML and roslaunch write 5 for 5.0.
//   - std::string takes an int, as its decimal text: roslaunch and rosparam make an int of any
//     value that looks like one, and a folder named 20261206 is plausible. The text can differ
//     from what was typed (007 -> "7", YAML's 0123 is octal 83), so `note` says which text was
//     used. A double is refused (1.50 arrives as 1.5: the text is lost), and so is a bool.
template <typename T>
T ParamValue(const XmlRpc::XmlRpcValue& v, const std::string& name, std::string* note = nullptr);

// A path parameter as the node will use it. Inputs: `what` names it in the log ("sdn_node:
// ~model"), `value` is the parameter's text. Output: `value` when empty or absolute; else the
// absolute path it names from the node's working folder, said in a WARN. roslaunch runs nodes in
// ROS_HOME, not the folder it was typed in: `model:=runs/x/model.pt` was retried for ever as
// "cannot open runs/x/model.json", and a relative summary went to ROS_HOME while its name was printed.
std::string AbsolutePathParam(const std::string& what, const std::string& value);

// AbsolutePathParam for a file the node writes when it ends (a report's summary, a plot): throws
// std::invalid_argument naming `what` when the path is a folder or its folder does not exist, so
// a mistyped path fails at start rather than after the whole replay, with a temporary name.
std::string OutputFileParam(const std::string& what, const std::string& value);

// The private parameters among `names` (full names, as ros::param::getParamNames gives them)
// that lie under `private_ns` ("/clip_buffer") and whose first key below it is not in `asked`.
// Returns each such key once, sorted, as "~key" ("/clip_buffer/rate/x" gives "~rate").
std::vector<std::string> UnreadParams(const std::vector<std::string>& names, const std::string& private_ns,
                                      const std::set<std::string>& asked);

// A node's private parameters, read strictly, remembering which were asked for.
class StrictParams {
 public:
  explicit StrictParams(const ros::NodeHandle& pnh) : pnh_(pnh) {}

  // ~name, or `fallback` when it is not set. Throws ParamError (see ParamValue). An int read as
  // text is logged (ROS_WARN) with the text used.
  template <typename T>
  T Get(const std::string& name, const T& fallback);
  std::string Get(const std::string& name, const char* fallback) { return Get<std::string>(name, fallback); }

  // Whether ~name is set; counts it as read.
  bool Has(const std::string& name);

  // Counts ~name as read without reading it: parameters a library reads from the node's private
  // namespace (diagnostic_updater's ~diagnostic_period).
  void Known(const std::string& name) { asked_.insert(name); }

  // Warns once, prefixed with `who`, naming the private parameters that are set and that neither
  // Get, Has nor Known asked for, nor that name a topic the node advertises (image_transport's
  // plugins keep their parameters under it). Call after the node has read its parameters and
  // advertised its topics.
  void WarnUnread(const std::string& who) const;

 private:
  ros::NodeHandle pnh_;
  std::set<std::string> asked_;
};

extern template bool StrictParams::Get<bool>(const std::string&, const bool&);
extern template int StrictParams::Get<int>(const std::string&, const int&);
extern template double StrictParams::Get<double>(const std::string&, const double&);
extern template std::string StrictParams::Get<std::string>(const std::string&, const std::string&);
extern template std::vector<double> StrictParams::Get<std::vector<double>>(const std::string&,
                                                                           const std::vector<double>&);

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_STRICT_PARAM_H_
