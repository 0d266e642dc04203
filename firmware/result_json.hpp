// The result set as the JSON fields of a "RESULT {...}" line: what the simulator board and the
// demo node print beside the CAN frames they send, so that tests read the poses the frames carry.
#pragma once

#include <cstdio>

#include "firmware/result_codec.hpp"

namespace sh::protocol {

// Writes `"sequence": S, "request_id": R, "status": C, "processing_time_us": T, "objects": [...]`
// without the enclosing braces, so a caller can add its own fields after it. Doubles are written
// with 17 significant digits, so a reader gets the exact values that were encoded.
void WriteResultSetJsonFields(std::FILE* out, const ResultSet& set);

}  // namespace sh::protocol
