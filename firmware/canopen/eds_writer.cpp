#include "firmware/canopen/eds_writer.hpp"

#include <cinttypes>

#include "firmware/canopen/object_dictionary.hpp"
#include "firmware/canopen/od_table.hpp"

namespace sh::canopen {
namespace {

// The date of the dictionary's last change: a manager compares EDS files by it. Update with
// every change of od_table.hpp.
constexpr const char* kEdsDate = "01-15-2026";  // mm-dd-yyyy (CiA 306)
constexpr const char* kEdsTime = "12:00PM";
constexpr int kEdsFileVersion = 1;

enum class Section { kMandatory, kOptional, kManufacturer };

Section SectionOf(uint16_t index) {
  if (index == kIdxDeviceType || index == kIdxErrorRegister || index == kIdxIdentity) {
    return Section::kMandatory;
  }
  return index < 0x2000 ? Section::kOptional : Section::kManufacturer;
}

// The EDS DefaultValue of an entry of a dictionary at its defaults: strings as text, COB-IDs as
// $NODEID+offset, unsigned values in hex, signed ones in decimal.
void WriteDefault(std::FILE* out, const OdEntry& e, const ObjectDictionary& od) {
  if (e.type() == DataType::kVisibleString) {
    std::fprintf(out, "DefaultValue=%s\n", od.GetString(e.index, e.sub));
  } else if (e.row->node_id_relative) {
    std::fprintf(out, "DefaultValue=$NODEID+0x%" PRIX64 "\n", static_cast<uint64_t>(e.row->value));
  } else if (IsSigned(e.type())) {
    std::fprintf(out, "DefaultValue=%" PRId64 "\n", ObjectDictionary::Decode(e.type(), e.value));
  } else {
    std::fprintf(out, "DefaultValue=0x%" PRIX32 "\n", e.value);
  }
}

void WriteEntry(std::FILE* out, const OdEntry& e, const ObjectDictionary& od, bool sub_section,
                const char* name) {
  if (sub_section) {
    std::fprintf(out, "[%04Xsub%X]\n", e.index, e.sub);
  } else {
    std::fprintf(out, "[%04X]\n", e.index);
  }
  std::fprintf(out, "ParameterName=%s\n", name);
  std::fprintf(out, "ObjectType=0x7\n");
  std::fprintf(out, "DataType=0x%04X\n", static_cast<unsigned>(e.type()));
  std::fprintf(out, "AccessType=%s\n", AccessName(e.access()));
  WriteDefault(out, e, od);
  std::fprintf(out, "PDOMapping=%d\n", e.row->pdo ? 1 : 0);
  if (e.row->has_limits) {
    std::fprintf(out, "LowLimit=%" PRId64 "\nHighLimit=%" PRId64 "\n", e.row->low, e.row->high);
  }
  std::fprintf(out, "\n");
}

// Object name; repeated objects are numbered ("Result object 3").
void ObjectName(const OdEntry& first, char* name, size_t capacity) {
  if (first.object->repeat > 1) {
    std::snprintf(name, capacity, "%s %u", first.object->name, first.instance);
  } else {
    std::snprintf(name, capacity, "%s", first.object->name);
  }
}

// Writes the list and the objects of one section.
void WriteSection(std::FILE* out, const ObjectDictionary& od, Section section, const char* title) {
  // Object list: the first entry of each object.
  size_t objects = 0;
  for (size_t i = 0; i < od.size(); ++i) {
    const OdEntry& e = od.entry(i);
    if (e.sub == 0 && SectionOf(e.index) == section) ++objects;
  }
  std::fprintf(out, "[%s]\nSupportedObjects=%zu\n", title, objects);
  size_t n = 0;
  for (size_t i = 0; i < od.size(); ++i) {
    const OdEntry& e = od.entry(i);
    if (e.sub == 0 && SectionOf(e.index) == section)
      std::fprintf(out, "%zu=0x%04X\n", ++n, e.index);
  }
  std::fprintf(out, "\n");

  size_t i = 0;
  while (i < od.size()) {
    const OdEntry& first = od.entry(i);
    size_t end = i + 1;
    while (end < od.size() && od.entry(end).index == first.index) ++end;
    if (SectionOf(first.index) == section) {
      char name[96];
      ObjectName(first, name, sizeof(name));
      if (first.object->code == ObjectCode::kVar) {
        WriteEntry(out, first, od, false, name);
      } else {
        std::fprintf(out, "[%04X]\nParameterName=%s\nObjectType=0x%X\nSubNumber=0x%zX\n\n",
                     first.index, name, static_cast<unsigned>(first.object->code), end - i);
        for (size_t s = i; s < end; ++s) {
          const OdEntry& e = od.entry(s);
          char sub_name[96];
          if (e.row->sub_repeat > 1) {
            std::snprintf(sub_name, sizeof(sub_name), "%s %d", e.row->name,
                          e.sub - e.row->sub + e.row->number_from);
          } else {
            std::snprintf(sub_name, sizeof(sub_name), "%s", e.row->name);
          }
          WriteEntry(out, e, od, true, sub_name);
        }
      }
    }
    i = end;
  }
}

}  // namespace

Status WriteEds(std::FILE* out) {
  static ObjectDictionary od;  // defaults; 30 KiB kept off the stack
  std::fprintf(out,
               "[FileInfo]\n"
               "FileName=stereohash.eds\n"
               "FileVersion=%d\n"
               "FileRevision=%u\n"
               "EDSVersion=4.0\n"
               "Description=stereohash stereo vision sensor: 6-D poses of recognised objects\n"
               "CreationTime=%s\nCreationDate=%s\nCreatedBy=stereohash\n"
               "ModificationTime=%s\nModificationDate=%s\nModifiedBy=stereohash\n\n",
               kEdsFileVersion, kRevisionNumber & 0xFFFF, kEdsTime, kEdsDate, kEdsTime, kEdsDate);
  int rx = 0, tx = 0;
  for (size_t i = 0; i < od.size(); ++i) {
    const OdEntry& e = od.entry(i);
    if (e.sub != 0) continue;
    if (e.index >= kIdxRpdoComm && e.index < kIdxRpdoComm + 0x200) ++rx;
    if (e.index >= kIdxTpdoComm && e.index < kIdxTpdoComm + 0x200) ++tx;
  }
  std::fprintf(out,
               "[DeviceInfo]\n"
               "VendorName=stereohash\n"
               "VendorNumber=0x%08X\n"
               "ProductName=stereohash stereo vision sensor\n"
               "ProductNumber=0x%08X\n"
               "RevisionNumber=0x%08X\n"
               "OrderCode=stereohash\n"
               "BaudRate_10=1\nBaudRate_20=1\nBaudRate_50=1\nBaudRate_125=1\nBaudRate_250=1\n"
               "BaudRate_500=1\nBaudRate_800=1\nBaudRate_1000=1\n"
               "SimpleBootUpMaster=0\n"
               "SimpleBootUpSlave=1\n"
               "Granularity=0\n"
               "DynamicChannelsSupported=0\n"
               "GroupMessaging=0\n"
               "NrOfRXPDO=%d\n"
               "NrOfTXPDO=%d\n"
               "LSS_Supported=1\n\n",
               kVendorId, kProductCode, kRevisionNumber, rx, tx);
  std::fprintf(out, "[DummyUsage]\n");
  for (int d = 1; d <= 7; ++d) std::fprintf(out, "Dummy%04X=0\n", d);
  std::fprintf(out,
               "\n[Comments]\nLines=4\n"
               "Line1=Result modes (0x2000 sub 4): 0 stream (TPDO1 header, TPDO2 multiplexed\n"
               "Line2=object parts, TPDO3 end with CRC-8), 1 PDO (write RPDO2 = counter, object\n"
               "Line3=index; the answer follows in TPDO5..8), 2 both. PDO mappings are fixed.\n"
               "Line4=Bit rate: set on the CAN interface of the board; LSS cannot change it.\n\n");
  WriteSection(out, od, Section::kMandatory, "MandatoryObjects");
  WriteSection(out, od, Section::kOptional, "OptionalObjects");
  WriteSection(out, od, Section::kManufacturer, "ManufacturerObjects");
  if (std::ferror(out)) return Status::Error(StatusCode::kUnavailable, "EDS: write error");
  return Status::Ok();
}

}  // namespace sh::canopen
