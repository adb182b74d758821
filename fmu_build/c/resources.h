/* The path of a file in the FMU's resources folder, from the fmuResourceLocation URI the
   importer gives fmi2Instantiate (shared by nodeforce_fmu.c and guard.c). */
#ifndef NODEFORCE_RESOURCES_H
#define NODEFORCE_RESOURCES_H

#include <stdlib.h>
#include <string.h>

/* "file:///a/b%20c/" + name -> "/a/b c/name" (malloc'ed; NULL if memory ran out). */
static inline char *resource_path(const char *uri, const char *name) {
    const char *p = uri;
    char *path, *out;
    if (strncmp(p, "file://", 7) == 0) {
        p += 7;
        if (strncmp(p, "localhost/", 10) == 0) p += 9;
    } else if (strncmp(p, "file:", 5) == 0) {
        p += 5;
    }
    path = malloc(strlen(p) + strlen(name) + 2);
    if (!path) return NULL;
    for (out = path; *p; p++) { /* percent-decoding */
        if (p[0] == '%' && p[1] && p[2]) {
            char hex[3] = {p[1], p[2], 0};
            *out++ = (char)strtol(hex, NULL, 16);
            p += 2;
        } else {
            *out++ = *p;
        }
    }
    if (out > path && out[-1] == '/') out--;
    *out++ = '/';
    strcpy(out, name);
    return path;
}

#endif
