#ifndef STEREOHASH_TESTS_SUPPORT_WORKLOAD_HPP_
#define STEREOHASH_TESTS_SUPPORT_WORKLOAD_HPP_

// How much repetition a test can afford in this build. A property shown by repeating an action
// (frames without a heap allocation, triggers answered) is shown in full by the release builds;
// under AddressSanitizer or ThreadSanitizer each frame costs tens of times more, and what those
// runs look for (a memory error, a data race) shows in the first few repetitions, every code path
// of the loop included. Such tests repeat Repetitions(full, instrumented) times.

namespace sh::testing {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kInstrumentedBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
inline constexpr bool kInstrumentedBuild = true;
#else
inline constexpr bool kInstrumentedBuild = false;
#endif
#else
inline constexpr bool kInstrumentedBuild = false;
#endif

// `full` in the release builds (host and board), `instrumented` under a sanitizer.
constexpr int Repetitions(int full, int instrumented) {
  return kInstrumentedBuild ? instrumented : full;
}

}  // namespace sh::testing

#endif  // STEREOHASH_TESTS_SUPPORT_WORKLOAD_HPP_
