#include "firmware/web/web_assets.hpp"

#include <cstring>

extern "C" const uint8_t stereohash_web_index_html[], stereohash_web_index_html_end[];
extern "C" const uint8_t stereohash_web_app_js[], stereohash_web_app_js_end[];
extern "C" const uint8_t stereohash_web_style_css[], stereohash_web_style_css_end[];
extern "C" const uint8_t stereohash_web_dbc[], stereohash_web_dbc_end[];

namespace sh::fw::web {
namespace {

size_t Bytes(const uint8_t* begin, const uint8_t* end) { return static_cast<size_t>(end - begin); }

}  // namespace

const Asset* FindAsset(const char* path) {
  static const Asset kAssets[] = {
      {"/", "text/html; charset=utf-8", stereohash_web_index_html,
       Bytes(stereohash_web_index_html, stereohash_web_index_html_end)},
      {"/app.js", "text/javascript; charset=utf-8", stereohash_web_app_js,
       Bytes(stereohash_web_app_js, stereohash_web_app_js_end)},
      {"/style.css", "text/css; charset=utf-8", stereohash_web_style_css,
       Bytes(stereohash_web_style_css, stereohash_web_style_css_end)},
  };
  for (const Asset& a : kAssets) {
    if (std::strcmp(a.path, path) == 0) return &a;
  }
  return nullptr;
}

Asset DbcAsset() {
  return {"/api/dbc", "text/plain; charset=utf-8", stereohash_web_dbc,
          Bytes(stereohash_web_dbc, stereohash_web_dbc_end)};
}

}  // namespace sh::fw::web
