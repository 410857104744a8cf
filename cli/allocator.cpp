// The polydg program's memory allocator: jemalloc (linked into this executable only, not into the
// library or the Python module), with transparent huge pages for the large arrays only.
//
// Meshing builds hundreds of MB of small, short-lived buffers (plane splits, faces, element
// lists) and solving allocates K and its preconditioner once, large. With glibc's malloc on
// 4 KiB pages, `polydg mesh` of a 75k-triangle scan at 64 cells spent about a third of its wall
// time in page faults; jemalloc reuses the small buffers' pages. Huge pages are asked for where
// a large array is made (makeResident in util/resident.h, adviseHugePages for K), not for the
// whole heap: a heap on huge pages ("thp:always") counts every partly used 2 MB page in full,
// 25 MiB more at the peak of meshing the bunny at 200 cells for no measurable time.
// jemalloc reads this string when it starts (before main), then /etc/malloc.conf, then the
// environment variable MALLOC_CONF, each overriding the one before: a user who wants other
// settings sets MALLOC_CONF.
extern "C" {
// NOLINTNEXTLINE(readability-identifier-naming): the name jemalloc looks for.
extern const char* malloc_conf;
const char* malloc_conf = "thp:default,metadata_thp:disabled";
}
