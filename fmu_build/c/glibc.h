/* The glibc symbol versions the Python FMU's binary asks for (see guard.c). */
#ifndef NODEFORCE_GLIBC_H
#define NODEFORCE_GLIBC_H

/* glibc 2.34 moved the dl* functions into libc under a new version, GLIBC_2.34, which a guard
   linked there would need; their first versions are still in every glibc (in libdl.so.2 before
   2.34, which the guard links, as compatibility symbols of libc since), so it asks for those.
   memcpy too (GLIBC_2.14 is its newer version). The guard then needs only glibc's first x86_64
   version, GLIBC_2.2.5: objdump -T of the binary lists every version it needs
   (tests/test_fmu_exchange.py reads them). Included after the system headers, which define
   __GLIBC__, by the C files of the Python FMU's binary (guard.c, fmi3.c). */
#if defined(__x86_64__) && defined(__GLIBC__)
__asm__(".symver dlopen,dlopen@GLIBC_2.2.5");
__asm__(".symver dlsym,dlsym@GLIBC_2.2.5");
__asm__(".symver dladdr,dladdr@GLIBC_2.2.5");
__asm__(".symver dlclose,dlclose@GLIBC_2.2.5");
__asm__(".symver dlerror,dlerror@GLIBC_2.2.5");
__asm__(".symver memcpy,memcpy@GLIBC_2.2.5");
#endif

#endif
