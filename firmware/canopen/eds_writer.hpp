// Electronic data sheet (CiA 306 EDS, version 4.0) of the sensor, written from the same table as
// the runtime dictionary (od_table.hpp), so the file a manager imports always describes the
// firmware that runs. The build writes it to stereohash.eds and installs it to
// share/stereohash/ (tools: stereohash-eds).
#pragma once

#include <cstdio>

#include "recog/base/status.hpp"

namespace sh::canopen {

// Writes the EDS to `out`. kUnavailable if the stream reports a write error.
Status WriteEds(std::FILE* out);

}  // namespace sh::canopen
