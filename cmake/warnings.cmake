# Warnings for our own targets only (arpipe_warnings is linked PRIVATE by every target).
add_library(arpipe_warnings INTERFACE)
target_compile_options(arpipe_warnings INTERFACE -Wall -Wextra -Wpedantic)
if(ARPIPE_WERROR)
  target_compile_options(arpipe_warnings INTERFACE -Werror)
endif()
if(ARPIPE_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
  # Checks of UBSan to leave out, e.g. "null,alignment,vptr": those three instrument every member
  # access and double GCC's compile time (CI leaves them out; ASan still reports a null dereference).
  set(ARPIPE_SANITIZE_SKIP "" CACHE STRING "UndefinedBehaviorSanitizer checks left out (-fno-sanitize=...)")
  if(ARPIPE_SANITIZE_SKIP)
    add_compile_options(-fno-sanitize=${ARPIPE_SANITIZE_SKIP})
  endif()
endif()
if(ARPIPE_FUZZ)
  # libFuzzer (docs/FUZZING.md): every library gets coverage instrumentation and the sanitizers;
  # the targets in tests/fuzz link -fsanitize=fuzzer themselves (it brings libFuzzer's main).
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "ARPIPE_FUZZ needs clang (CC=clang-14 CXX=clang++-14): libFuzzer is part of clang")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                      -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
