// Strict field parsing shared by the anemometer protocols: a field is either empty (the
// instrument's "no value") or a complete finite number; anything else is an error.
#ifndef CLOTHWIND_SENSORS_PROTOCOL_FIELDS_H_
#define CLOTHWIND_SENSORS_PROTOCOL_FIELDS_H_

#include <string>
#include <vector>

namespace clothwind::sensors {

// Parses a decimal number field, allowing surrounding spaces.
// Inputs:
//   field  text of the field
// Outputs:
//   value  the number, or NaN for an empty field
//   error  why it failed (quotes the field)
// Returns false when the field is neither empty nor a complete finite number.
bool ParseOptionalNumber(const std::string& field, double* value, std::string* error);

// Removes leading and trailing spaces and tabs.
std::string TrimSpaces(const std::string& s);

// Splits a record at every comma: "a,,b" gives {"a", "", "b"} and "" gives {""}, so field
// positions stay those of the protocol even where a field is empty.
// Inputs:
//   s            the record (without framing, e.g. no '$' or checksum)
//   trim_spaces  whether to strip spaces and tabs around each field
// Returns the fields, one more than the number of commas.
std::vector<std::string> SplitCommas(const std::string& s, bool trim_spaces);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_PROTOCOL_FIELDS_H_
