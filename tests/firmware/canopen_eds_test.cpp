// The EDS written from the declared table: every dictionary entry has its section with the
// entry's type, access, mapping flag and default, the object lists name each object once, and
// the device information matches the identity. (tests/node/ loads the same file with
// node-canopen's EDS parser, which did not write it.)
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "firmware/canopen/eds_writer.hpp"
#include "firmware/canopen/object_dictionary.hpp"

namespace sh::canopen {
namespace {

using Ini = std::map<std::string, std::map<std::string, std::string>>;

Ini ParseIni(const std::string& text) {
  Ini ini;
  std::istringstream in(text);
  std::string line, section;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (line.front() == '[') {
      section = line.substr(1, line.find(']') - 1);
      EXPECT_EQ(ini.count(section), 0u) << "section [" << section << "] twice";
      ini[section];
      continue;
    }
    const size_t eq = line.find('=');
    EXPECT_NE(eq, std::string::npos) << line;
    if (eq == std::string::npos) continue;
    const std::string key = line.substr(0, eq);
    EXPECT_EQ(ini[section].count(key), 0u) << section << ": " << key << " twice";
    ini[section][key] = line.substr(eq + 1);
  }
  return ini;
}

std::string Eds() {
  char* buffer = nullptr;
  size_t size = 0;
  std::FILE* f = open_memstream(&buffer, &size);
  EXPECT_TRUE(WriteEds(f).ok());
  std::fclose(f);
  std::string text(buffer, size);
  free(buffer);
  return text;
}

std::string Key(const OdEntry& e) {
  char key[16];
  if (e.object->code == ObjectCode::kVar) {
    std::snprintf(key, sizeof(key), "%04X", e.index);
  } else {
    std::snprintf(key, sizeof(key), "%04Xsub%X", e.index, e.sub);
  }
  return key;
}

TEST(CanopenEds, EveryEntryIsDescribedAsTheDictionaryHasIt) {
  const Ini ini = ParseIni(Eds());
  auto od = std::make_unique<ObjectDictionary>();
  for (size_t i = 0; i < od->size(); ++i) {
    const OdEntry& e = od->entry(i);
    const auto it = ini.find(Key(e));
    ASSERT_NE(it, ini.end()) << Key(e);
    const auto& s = it->second;
    EXPECT_EQ(std::stoul(s.at("DataType"), nullptr, 16), static_cast<unsigned>(e.type())) << Key(e);
    EXPECT_EQ(s.at("AccessType"), AccessName(e.access())) << Key(e);
    EXPECT_EQ(s.at("PDOMapping"), e.row->pdo ? "1" : "0") << Key(e);
    const std::string def = s.at("DefaultValue");
    if (e.type() == DataType::kVisibleString) {
      EXPECT_EQ(def, od->GetString(e.index, e.sub)) << Key(e);
    } else if (e.row->node_id_relative) {
      ASSERT_EQ(def.rfind("$NODEID+", 0), 0u) << Key(e);
      EXPECT_EQ(std::stoll(def.substr(8), nullptr, 0) + 1, od->Get(e.index, e.sub)) << Key(e);
    } else {
      EXPECT_EQ(std::stoll(def, nullptr, 0), ObjectDictionary::Decode(e.type(), e.value)) << Key(e);
    }
  }
}

TEST(CanopenEds, ObjectListsAndSubNumbersAgreeWithTheDictionary) {
  const Ini ini = ParseIni(Eds());
  auto od = std::make_unique<ObjectDictionary>();
  std::map<uint16_t, size_t> subs;
  for (size_t i = 0; i < od->size(); ++i) ++subs[od->entry(i).index];
  size_t listed = 0;
  for (const char* list : {"MandatoryObjects", "OptionalObjects", "ManufacturerObjects"}) {
    const auto& s = ini.at(list);
    const size_t n = std::stoul(s.at("SupportedObjects"));
    EXPECT_EQ(s.size(), n + 1) << list;
    for (size_t k = 1; k <= n; ++k) {
      const uint16_t index =
          static_cast<uint16_t>(std::stoul(s.at(std::to_string(k)), nullptr, 16));
      ASSERT_EQ(subs.count(index), 1u) << list << " names 0x" << std::hex << index;
      char key[8];
      std::snprintf(key, sizeof(key), "%04X", index);
      const auto& obj = ini.at(key);
      if (obj.count("SubNumber")) {
        EXPECT_EQ(std::stoul(obj.at("SubNumber"), nullptr, 16), subs[index]) << key;
        EXPECT_EQ(obj.count("DataType"), 0u) << key;  // CiA 306: not for RECORD/ARRAY
      }
      ++listed;
    }
  }
  EXPECT_EQ(listed, subs.size());
  EXPECT_EQ(ini.at("MandatoryObjects").at("1"), "0x1000");
  EXPECT_EQ(ini.at("MandatoryObjects").at("2"), "0x1001");
  EXPECT_EQ(ini.at("MandatoryObjects").at("3"), "0x1018");
}

TEST(CanopenEds, DeviceInfoMatchesTheIdentityObject) {
  const Ini ini = ParseIni(Eds());
  const auto& info = ini.at("DeviceInfo");
  EXPECT_EQ(std::stoul(info.at("VendorNumber"), nullptr, 16), kVendorId);
  EXPECT_EQ(std::stoul(info.at("ProductNumber"), nullptr, 16), kProductCode);
  EXPECT_EQ(std::stoul(info.at("RevisionNumber"), nullptr, 16), kRevisionNumber);
  EXPECT_EQ(info.at("NrOfTXPDO"), std::to_string(kTpdoCount));
  EXPECT_EQ(info.at("NrOfRXPDO"), std::to_string(kRpdoCount));
  EXPECT_EQ(info.at("LSS_Supported"), "1");
  EXPECT_EQ(ini.at("FileInfo").at("EDSVersion"), "4.0");
}

}  // namespace
}  // namespace sh::canopen
