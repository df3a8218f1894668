// FOXI_API marks foxi's public entry points: the functions and classes of the public headers that a
// host program calls. The libraries are compiled with hidden visibility (CXX_VISIBILITY_PRESET
// hidden, VISIBILITY_INLINES_HIDDEN), so a shared libfoxi_*.so exports these and nothing else: the
// internals (foxi/*/src, CGAL's and TetGen's instantiations) stay out of its dynamic symbol table.
// In a static build the mark changes nothing for linking foxi itself, and keeps the internals hidden
// when a host links the static libraries into a shared library of its own.
//
// foxi builds on POSIX systems only (fork, poll, mmap), where one mark serves both for building the
// libraries and for using them (ELF and Mach-O have no separate import declaration).
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define FOXI_API __attribute__((visibility("default")))
#else
#define FOXI_API
#endif
