#include "firmware/result_json.hpp"

namespace sh::protocol {

void WriteResultSetJsonFields(std::FILE* out, const ResultSet& set) {
  std::fprintf(out,
               "\"sequence\": %u, \"request_id\": %u, \"status\": %u, \"processing_time_us\": %u, "
               "\"objects\": [",
               set.sequence, set.request_id, static_cast<unsigned>(set.status),
               set.processing_time_us);
  for (int i = 0; i < set.object_count; ++i) {
    const ObjectPose& p = set.objects[i];
    std::fprintf(out,
                 "%s{\"model_id\": %u, \"instance\": %u, \"score\": %.17g, "
                 "\"t_mm\": [%.17g, %.17g, %.17g], \"q_wxyz\": [%.17g, %.17g, %.17g, %.17g]}",
                 i ? ", " : "", p.model_id, p.instance, p.score, p.cam_t_model_mm[0],
                 p.cam_t_model_mm[1], p.cam_t_model_mm[2], p.cam_q_model[0], p.cam_q_model[1],
                 p.cam_q_model[2], p.cam_q_model[3]);
  }
  std::fputc(']', out);
}

}  // namespace sh::protocol
