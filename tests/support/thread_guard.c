// Preloaded (LD_PRELOAD) into the host build's test programs that are not marked THREADS, and into
// the part of a program with THREAD_CASES that runs the other cases: a program that starts a
// thread stops with a message naming the test, so that every test that runs threads is in the
// ThreadSanitizer run (which selects the THREADS mark). The guard removes itself
// from the environment at start, so programs a test starts (stereohash, the simulator) are free
// to run their own threads.
#define _GNU_SOURCE
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char g_command[512];

__attribute__((constructor)) static void ForgetPreload(void) {
  unsetenv("LD_PRELOAD");
  FILE* f = fopen("/proc/self/cmdline", "r");
  if (f == NULL) return;
  const size_t n = fread(g_command, 1, sizeof g_command - 1, f);
  fclose(f);
  for (size_t i = 0; i < n; ++i) {
    if (g_command[i] == '\0') g_command[i] = ' ';
  }
  g_command[n] = '\0';
}

int pthread_create(pthread_t* thread, const pthread_attr_t* attr, void* (*start)(void*),
                   void* arg) {
  static const char kMessage[] =
      "thread guard: this test starts a thread, but neither is its program marked THREADS nor "
      "its case named in THREAD_CASES in its CMakeLists.txt (stereohash_add_test), so "
      "ThreadSanitizer would not run it:\n  ";
  (void)thread;
  (void)attr;
  (void)start;
  (void)arg;
  (void)!write(2, kMessage, sizeof kMessage - 1);
  (void)!write(2, g_command, strlen(g_command));
  (void)!write(2, "\n", 1);
  _exit(3);
}
