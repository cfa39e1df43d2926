// What a fuzz target does when a parser returns something it promised never to return: print the
// promise that was broken and abort, which libFuzzer reports as a crash with this input.
#pragma once

#include <cstdio>
#include <cstdlib>

#define ARPIPE_FUZZ_CHECK(condition, what)                                                 \
  do {                                                                                     \
    if (!(condition)) {                                                                    \
      std::fprintf(stderr, "arpipe fuzz: broken promise: %s (%s)\n", what, #condition);    \
      std::abort();                                                                        \
    }                                                                                      \
  } while (false)
