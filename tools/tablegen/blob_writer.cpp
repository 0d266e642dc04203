#include "tools/tablegen/blob_writer.hpp"

#include <algorithm>

namespace sh {

std::vector<uint32_t> SortByBin(const std::vector<uint32_t>& bin_of_item, uint32_t bins,
                                std::vector<uint32_t>* order, uint32_t* max_per_bin) {
  std::vector<uint32_t> offsets(bins + 1, 0);
  for (uint32_t b : bin_of_item) ++offsets[b + 1];
  *max_per_bin = 0;
  for (uint32_t i = 0; i < bins; ++i) {
    *max_per_bin = std::max(*max_per_bin, offsets[i + 1]);
    offsets[i + 1] += offsets[i];
  }
  std::vector<uint32_t> cursor(offsets.begin(), offsets.end() - 1);
  order->assign(bin_of_item.size(), 0);
  for (uint32_t i = 0; i < bin_of_item.size(); ++i) (*order)[cursor[bin_of_item[i]]++] = i;
  return offsets;
}

}  // namespace sh
