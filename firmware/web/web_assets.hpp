// The files of the page, linked into the program (web_assets.S): the page works without any
// network beyond the board, and no request can name a file of the board's file system.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sh::fw::web {

struct Asset {
  const char* path;  // as requested ("/", "/app.js")
  const char* content_type;
  const uint8_t* data;
  size_t bytes;
};

// The page's file at exactly `path`, or nullptr.
const Asset* FindAsset(const char* path);
// The DBC of the CAN protocol (firmware/stereohash.dbc).
Asset DbcAsset();

}  // namespace sh::fw::web
