// The project's one include of tomlplusplus (Debian 12's 3.3, header-only in each user): every
// file that parses or writes TOML includes this instead of <toml++/toml.h>, so every translation
// unit sees the library configured the same way (its inline functions must not differ between
// them).
//
// The library states its parsers' preconditions with TOML_ASSERT_ASSUME: assert() in builds
// without NDEBUG, TOML_ASSUME (__builtin_assume) with NDEBUG under clang, nothing under GCC.
// Hostile text breaks several of them (docs/reliability.md), which aborts a debug build and is
// undefined behaviour in a clang release build, while the GCC release builds that ship go on to
// the library's own syntax error. Both are defined away here, so every build parses as the
// shipped one does, and the fuzzers (ASan + UBSan) check that path. What is undefined in every
// build (its whitespace test's __builtin_unreachable) is kept away by safe_parse's scan.
#pragma once

#ifndef TOML_ASSERT
#define TOML_ASSERT(expr) static_assert(true)
#endif
#include <toml++/impl/preprocessor.h>
#undef TOML_ASSUME
#define TOML_ASSUME(...) static_assert(true)
#include <toml++/toml.h>
