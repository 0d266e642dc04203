// libFuzzer target: the CANopen services of the sensor take arbitrary frames from the bus. The
// input is a sequence of frames (2 bytes id, 1 byte length, up to 8 data bytes, one time step)
// fed to the SDO server, the LSS slave and the RPDO unpacker of one dictionary, as a manager
// would. Nothing may crash or read out of bounds; every answer is a well-formed 8-byte frame on
// the right identifier, and read-only entries keep their values.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>

#include "firmware/canopen/lss_slave.hpp"
#include "firmware/canopen/object_dictionary.hpp"
#include "firmware/canopen/od_table.hpp"
#include "firmware/canopen/pdo.hpp"
#include "firmware/canopen/sdo_server.hpp"

namespace {

class Store final : public sh::canopen::LssStore {
 public:
  sh::Status StoreNodeId(uint8_t) override { return sh::Status::Ok(); }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sh::canopen;
  static auto od = std::make_unique<ObjectDictionary>();
  od->ResetCommunication(5);
  SdoServer sdo(od.get(), 50);
  LssSlave lss;
  Store store;
  lss.Init(LssIdentity{0, kProductCode, kRevisionNumber, 77}, data[0] % 2 ? 5 : kNodeIdUnconfigured,
           &store);
  const uint32_t device_type = od->Get(kIdxDeviceType, 0);
  int64_t now = 0;
  size_t pos = size > 0 ? 1 : 0;
  while (pos + 3 <= size) {
    sh::hal::CanFrame f;
    // Mostly the identifiers that matter, any other now and then.
    const uint16_t raw_id = static_cast<uint16_t>(data[pos] | data[pos + 1] << 8);
    const uint32_t ids[] = {0x605, 0x7E5, 0x305, 0x205, raw_id & 0x7FFu};
    f.id = ids[raw_id % 5];
    f.len = static_cast<uint8_t>(data[pos + 2] % 9);
    pos += 3;
    for (uint8_t i = 0; i < f.len && pos < size; ++i) f.data[i] = data[pos++];
    now += 10'000'000;  // 10 ms per frame: some transfers time out
    sh::hal::CanFrame reply;
    if (sdo.Handle(f, now, &reply) && (reply.len != 8 || reply.id != 0x585)) std::abort();
    const LssOutcome o = lss.Handle(f, &reply);
    if (o.respond && (reply.len != 8 || reply.id != kLssSlaveCobId)) std::abort();
    const int rpdo = RpdoFor(*od, f);
    if (rpdo >= 0) (void)UnpackRpdo(od.get(), rpdo, f);
    if (sdo.Poll(now, &reply) && reply.data[0] != 0x80) std::abort();
  }
  if (od->Get(kIdxDeviceType, 0) != device_type) std::abort();  // read-only
  return 0;
}
