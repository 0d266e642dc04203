// The precompiled header of the test programs (tests/CMakeLists.txt) is built with this source;
// every test program reuses it.
