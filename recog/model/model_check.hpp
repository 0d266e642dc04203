// Validation of a Model record read from a blob (hash tables, feature database): every count
// within its capacity, every index in range, every coordinate finite, a NUL-terminated name.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh {

// kDataLoss naming `blob` (e.g. "table blob") and the model when the record is inconsistent.
Status ValidateModelRecord(const Model& m, uint32_t index, const char* blob);

}  // namespace sh
