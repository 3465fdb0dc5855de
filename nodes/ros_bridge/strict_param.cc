#include "ros_bridge/strict_param.h"

#include <ros/this_node.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace clothwind::ros_bridge {
namespace {

using XmlRpc::XmlRpcValue;

// XmlRpcValue's casts are non-const (they return references): read from a copy.
XmlRpcValue Copy(const XmlRpcValue& v) { return v; }

// The value as a message shows it: short, strings quoted (a quoted "5" is the usual slip).
std::string Shown(const XmlRpcValue& v) {
  XmlRpcValue c = v;
  char buffer[64];
  switch (c.getType()) {
    case XmlRpcValue::TypeBoolean: return static_cast<bool>(c) ? "true" : "false";
    case XmlRpcValue::TypeInt: return std::to_string(static_cast<int>(c));
    case XmlRpcValue::TypeDouble: {
      // The shortest text that reads back as the value: 0.1, not 0.10000000000000001.
      const double d = c;
      for (int digits = 6; digits <= 17; ++digits) {
        std::snprintf(buffer, sizeof buffer, "%.*g", digits, d);
        if (std::strtod(buffer, nullptr) == d) break;
      }
      return buffer;
    }
    case XmlRpcValue::TypeString: {
      const std::string& s = c;
      return "\"" + (s.size() > 60 ? s.substr(0, 57) + "..." : s) + "\"";
    }
    case XmlRpcValue::TypeArray: return "a list of " + std::to_string(c.size()) + " values";
    case XmlRpcValue::TypeStruct: return "a dictionary of " + std::to_string(c.size()) + " keys";
    default: return "?";
  }
}

// Why a value found where a number is expected may be one: a number written in quotes in YAML,
// or a launch file's value made a string with type="str".
std::string Hint(const XmlRpcValue& v, const std::string& expected) {
  if (v.getType() == XmlRpcValue::TypeString && expected != "string")
    return " (a value in quotes? write it without them in YAML, and without type=\"str\" in a launch file)";
  if (expected == "string" && (v.getType() == XmlRpcValue::TypeDouble || v.getType() == XmlRpcValue::TypeBoolean))
    return " (roslaunch and rosparam read a value that looks like a number or a bool as one: give it as "
           "<param type=\"str\"> in a launch file, or quote it in YAML)";
  return "";
}

// "a double", "an int".
std::string WithArticle(const std::string& what) { return (what.rfind("int", 0) == 0 ? "an " : "a ") + what; }

[[noreturn]] void Refuse(const XmlRpcValue& v, const std::string& name, const std::string& expected) {
  const bool container = v.getType() == XmlRpcValue::TypeArray || v.getType() == XmlRpcValue::TypeStruct;
  const std::string found =
      container ? Shown(v) : WithArticle(XmlRpcTypeName(v)) + " (" + Shown(v) + ")";
  throw ParamError(name + " is set to " + found + ", expected " + WithArticle(expected) + Hint(v, expected));
}

void ClearNote(std::string* note) {
  if (note) note->clear();
}

}  // namespace

std::string XmlRpcTypeName(const XmlRpc::XmlRpcValue& v) {
  switch (v.getType()) {
    case XmlRpcValue::TypeBoolean: return "bool";
    case XmlRpcValue::TypeInt: return "int";
    case XmlRpcValue::TypeDouble: return "double";
    case XmlRpcValue::TypeString: return "string";
    case XmlRpcValue::TypeDateTime: return "date";
    case XmlRpcValue::TypeBase64: return "binary";
    case XmlRpcValue::TypeArray: return "list";
    case XmlRpcValue::TypeStruct: return "dictionary";
    default: return "invalid value";
  }
}

template <>
bool ParamValue<bool>(const XmlRpcValue& v, const std::string& name, std::string* note) {
  ClearNote(note);
  XmlRpcValue c = Copy(v);
  if (c.getType() == XmlRpcValue::TypeBoolean) return static_cast<bool>(c);
  if (c.getType() == XmlRpcValue::TypeInt && (static_cast<int>(c) == 0 || static_cast<int>(c) == 1))
    return static_cast<int>(c) == 1;
  Refuse(v, name, "bool (true/false, or 1/0)");
}

template <>
int ParamValue<int>(const XmlRpcValue& v, const std::string& name, std::string* note) {
  ClearNote(note);
  XmlRpcValue c = Copy(v);
  if (c.getType() == XmlRpcValue::TypeInt) return static_cast<int>(c);
  Refuse(v, name, "int");
}

template <>
double ParamValue<double>(const XmlRpcValue& v, const std::string& name, std::string* note) {
  ClearNote(note);
  XmlRpcValue c = Copy(v);
  if (c.getType() == XmlRpcValue::TypeDouble) return static_cast<double>(c);
  if (c.getType() == XmlRpcValue::TypeInt) return static_cast<int>(c);
  Refuse(v, name, "double (or an int)");
}

template <>
std::string ParamValue<std::string>(const XmlRpcValue& v, const std::string& name, std::string* note) {
  ClearNote(note);
  XmlRpcValue c = Copy(v);
  if (c.getType() == XmlRpcValue::TypeString) return static_cast<std::string&>(c);
  if (c.getType() == XmlRpcValue::TypeInt) {
    const std::string text = std::to_string(static_cast<int>(c));
    if (note)
      *note = name + " is set to the int " + text + ", read as the text \"" + text +
              "\" (leading zeros or a YAML octal are lost that way: give it as <param type=\"str\"> or quote it)";
    return text;
  }
  Refuse(v, name, "string");
}

template <>
std::vector<double> ParamValue<std::vector<double>>(const XmlRpcValue& v, const std::string& name,
                                                    std::string* note) {
  ClearNote(note);
  if (v.getType() != XmlRpcValue::TypeArray) Refuse(v, name, "list of numbers");
  XmlRpcValue c = Copy(v);
  std::vector<double> out;
  for (int i = 0; i < c.size(); ++i) out.push_back(ParamValue<double>(c[i], name + "[" + std::to_string(i) + "]"));
  return out;
}

std::vector<std::string> UnreadParams(const std::vector<std::string>& names, const std::string& private_ns,
                                      const std::set<std::string>& asked) {
  std::string prefix = private_ns;
  if (prefix.empty() || prefix.back() != '/') prefix += '/';
  std::set<std::string> unread;
  for (const std::string& n : names) {
    if (n.size() <= prefix.size() || n.compare(0, prefix.size(), prefix) != 0) continue;
    // A dictionary parameter is stored as one name per leaf: its first key below the node names it.
    const std::string key = n.substr(prefix.size(), n.find('/', prefix.size()) - prefix.size());
    if (!key.empty() && !asked.count(key)) unread.insert("~" + key);
  }
  return {unread.begin(), unread.end()};
}

template <typename T>
T StrictParams::Get(const std::string& name, const T& fallback) {
  asked_.insert(name);
  XmlRpcValue v;
  if (!pnh_.getParam(name, v)) return fallback;
  std::string note;
  T value = ParamValue<T>(v, "~" + name, &note);
  if (!note.empty()) ROS_WARN("%s", note.c_str());
  return value;
}

template bool StrictParams::Get<bool>(const std::string&, const bool&);
template int StrictParams::Get<int>(const std::string&, const int&);
template double StrictParams::Get<double>(const std::string&, const double&);
template std::string StrictParams::Get<std::string>(const std::string&, const std::string&);
template std::vector<double> StrictParams::Get<std::vector<double>>(const std::string&, const std::vector<double>&);

bool StrictParams::Has(const std::string& name) {
  asked_.insert(name);
  return pnh_.hasParam(name);
}

void StrictParams::WarnUnread(const std::string& who) const {
  std::vector<std::string> names;
  if (!ros::param::getParamNames(names)) return;  // no master to ask: nothing to say
  // A topic this node advertises under its private namespace (sdn_node's ~power) is where
  // image_transport's plugins keep their parameters (~power/compressed/...): not a misspelling.
  std::set<std::string> known = asked_;
  std::vector<std::string> topics;
  ros::this_node::getAdvertisedTopics(topics);
  for (const std::string& t : UnreadParams(topics, pnh_.getNamespace(), {})) known.insert(t.substr(1));
  const std::vector<std::string> unread = UnreadParams(names, pnh_.getNamespace(), known);
  if (unread.empty()) return;
  std::string list;
  for (const std::string& u : unread) list += (list.empty() ? "" : ", ") + u;
  ROS_WARN("%s: private parameter%s %s set but not read by this node (misspelt?)", who.c_str(),
           unread.size() > 1 ? "s" : "", list.c_str());
}

std::string AbsolutePathParam(const std::string& what, const std::string& value) {
  if (value.empty() || std::filesystem::path(value).is_absolute()) return value;
  const std::string absolute = std::filesystem::absolute(value).lexically_normal().string();
  ROS_WARN("%s '%s' is relative: %s (the node's working folder, ROS_HOME under roslaunch; give an absolute path)",
           what.c_str(), value.c_str(), absolute.c_str());
  return absolute;
}

std::string OutputFileParam(const std::string& what, const std::string& value) {
  const std::string path = AbsolutePathParam(what, value);
  if (path.empty()) return path;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw std::invalid_argument(what + " '" + path + "' is a folder; expected a file name");
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (!std::filesystem::is_directory(folder, ec))
    throw std::invalid_argument(what + " '" + path + "': its folder " + folder.string() +
                                (std::filesystem::exists(folder, ec) ? " is not a folder" : " does not exist"));
  return path;
}

}  // namespace clothwind::ros_bridge
