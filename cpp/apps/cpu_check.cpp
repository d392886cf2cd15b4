// The command-line renderer's check that this CPU runs what the build was compiled for
// (CMakeLists.txt, MIPRASTER_X86_LEVEL). This file alone is compiled for the x86-64 baseline, and
// the check runs as the first constructor, before main and the other files' static initializers:
// on an older CPU the program says what is wrong instead of stopping on an illegal instruction.
#include <cstdio>
#include <cstdlib>

#if defined(MIPRASTER_X86_V3)
[[gnu::constructor(101)]] static void check_x86_64_v3() {
    __builtin_cpu_init();
    if (__builtin_cpu_supports("x86-64-v3")) return;
    std::fprintf(stderr,
                 "mipraster: error: this build was compiled for x86-64-v3 (AVX2), which this CPU does not have; "
                 "rebuild it with -DMIPRASTER_X86_LEVEL=baseline\n");
    std::exit(2);
}
#endif
