// The precompiled header of the board code's libraries (CMakeLists.txt, stereohash_board_pch) is
// built with this source; every library under recog/, tables/, hal/ and firmware/ reuses it.
