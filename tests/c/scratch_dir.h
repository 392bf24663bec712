/* A scratch directory for tests that write files: made beside the test executable, inside
 * the build directory (never /tmp, which other jobs on a shared machine may empty), and
 * removed with everything in it. For one test process, used from one thread. */
#pragma once

#include <dirent.h>
#include <ftw.h>
#include <libgen.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char scratch_dir[PATH_MAX];

/* The directory of the running test executable ("" if unknown). */
static const char *scratch_exe_dir(void) {
    static char dir[PATH_MAX];
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0) return "";
    exe[n] = '\0';
    snprintf(dir, sizeof dir, "%s", dirname(exe));
    return dir;
}

/* Creates <executable's directory>/<prefix>-XXXXXX as scratch_dir; 0 on success. */
static int scratch_create(const char *prefix) {
    const char *dir = scratch_exe_dir();
    if (!*dir) return -1;
    snprintf(scratch_dir, sizeof scratch_dir, "%s/%s-XXXXXX", dir, prefix);
    return mkdtemp(scratch_dir) ? 0 : -1;
}

/* scratch_dir/name; the last 16 results stay valid (a test holds a few paths at once). */
static const char *scratch_path(const char *name) {
    static char buf[16][PATH_MAX + 256];
    static int next = 0;
    char *p = buf[next++ % 16];
    snprintf(p, sizeof buf[0], "%s/%s", scratch_dir, name);
    return p;
}

static int scratch_remove_entry(const char *p, const struct stat *st, int flag, struct FTW *ftw) {
    (void)st, (void)flag, (void)ftw;
    return remove(p);
}

/* Removes scratch_dir and everything in it; 0 on success. */
static int scratch_remove(void) {
    return nftw(scratch_dir, scratch_remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

/* Entries of dir whose names start with prefix ("" counts every entry but . and ..), or -1
 * if dir cannot be read: what a failed write left behind. */
static int scratch_count(const char *dir, const char *prefix) {
    int n = 0;
    DIR *d = opendir(dir);
    struct dirent *e;
    if (!d) return -1;
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0 &&
            strncmp(e->d_name, prefix, strlen(prefix)) == 0)
            ++n;
    closedir(d);
    return n;
}
