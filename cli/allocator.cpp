// The polydg program's memory allocator: jemalloc (linked into this executable only, not into the
// library or the Python module), configured here to back the heap with transparent huge pages.
//
// Meshing builds hundreds of MB of small, short-lived buffers (plane splits, faces, element
// lists) and solving allocates K and its preconditioner once, large. With glibc's malloc on
// 4 KiB pages, `polydg mesh` of a 75k-triangle scan at 64 cells spent about a third of its wall
// time in page faults.
// jemalloc reads this string when it starts (before main), then /etc/malloc.conf, then the
// environment variable MALLOC_CONF, each overriding the one before: a user who wants other
// settings sets MALLOC_CONF. Where the system has transparent huge pages disabled ("never"),
// "thp:always" does nothing and the pages stay 4 KiB.
extern "C" {
// NOLINTNEXTLINE(readability-identifier-naming): the name jemalloc looks for.
extern const char* malloc_conf;
const char* malloc_conf = "thp:always,metadata_thp:auto";
}
