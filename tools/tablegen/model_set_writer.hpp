// Writes a model set (tables/model_set_format.hpp) from section blobs built by the kinds' own
// builders (host tools and the build step).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "recog/base/status.hpp"
#include "tables/model_set_format.hpp"

namespace sh {

struct ModelSetInput {
  uint32_t kind;  // SectionKind (another number for kinds this build does not know)
  const uint8_t* data;
  size_t size;
};

// The container holding `sections` in the order given, each payload copied byte for byte at the
// next multiple of kModelSetAlignment. Refuses no section, more than kMaxModelSetSections, a kind
// given twice, and a payload without the common blob header (or, for a known kind, another
// kind's magic), each with a message naming the section.
Result<std::vector<uint8_t>> BuildModelSet(const std::vector<ModelSetInput>& sections);

}  // namespace sh
