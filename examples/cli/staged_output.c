#define _GNU_SOURCE /* getdents64 */
#include "staged_output.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- messages ---- */

static void say(char *msg, size_t size, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, size, fmt, ap);
    va_end(ap);
}

static const char *doing(output_kind kind) {
    return kind == OUTPUT_MESH ? "cannot write mesh" : "cannot write oriented points";
}

static int fail_errno(const staged_output *out, int err, char *msg, size_t size) {
    say(msg, size, "%s: GMPU_ERROR_IO: %s: %s", doing(out->kind), out->given, strerror(err));
    return 0;
}

/* ---- checks before any work ---- */

/* The lower-cased extension of the file name, "" when it has none. */
static void extension_of(const char *path, char *ext, size_t size) {
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(path, '.');
    ext[0] = '\0';
    if (!dot || (slash && dot < slash)) return;
    size_t i = 0;
    for (const char *p = dot + 1; *p && i + 1 < size; ++p) ext[i++] = (char)tolower((unsigned char)*p);
    ext[i] = '\0';
}

/* The same lists as the library's writers (lib/io/format_dispatch.cpp). */
static int known_extension(output_kind kind, const char *ext) {
    if (kind == OUTPUT_MESH)
        return !strcmp(ext, "ply") || !strcmp(ext, "obj") || !strcmp(ext, "off") || !strcmp(ext, "stl") ||
               !strcmp(ext, "glb");
    return !strcmp(ext, "ply") || !strcmp(ext, "xyz");
}

/* The file a write to `given` replaces: symlinks followed (a link is written through, as
 * an editor does), the directory made absolute. -1 with errno when it cannot be resolved. */
static int resolve_target(const char *given, char *target) {
    char cur[PATH_MAX];
    if (strlen(given) >= sizeof cur) return errno = ENAMETOOLONG, -1;
    strcpy(cur, given);
    for (int hops = 0;; ++hops) {
        struct stat st;
        if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode)) break;
        if (hops == 40) return errno = ELOOP, -1;
        char link[PATH_MAX];
        ssize_t n = readlink(cur, link, sizeof link - 1);
        if (n < 0) return -1;
        link[n] = '\0';
        if (link[0] == '/') {
            strcpy(cur, link);
        } else { /* relative to the directory holding the link */
            char *slash = strrchr(cur, '/');
            size_t keep = slash ? (size_t)(slash - cur) + 1 : 0;
            if (keep + (size_t)n >= sizeof cur) return errno = ENAMETOOLONG, -1;
            memcpy(cur + keep, link, (size_t)n + 1);
        }
    }
    char *slash = strrchr(cur, '/');
    const char *base = slash ? slash + 1 : cur;
    if (!*base || !strcmp(base, ".") || !strcmp(base, "..")) return errno = EISDIR, -1;
    char dir[PATH_MAX], real_dir[PATH_MAX];
    if (!slash) strcpy(dir, ".");
    else if (slash == cur) strcpy(dir, "/");
    else memcpy(dir, cur, (size_t)(slash - cur)), dir[slash - cur] = '\0';
    if (!realpath(dir, real_dir)) return -1;
    struct stat st;
    if (stat(real_dir, &st) != 0) return -1;
    if (!S_ISDIR(st.st_mode)) return errno = ENOTDIR, -1;
    int n = snprintf(target, PATH_MAX, "%s/%s", strcmp(real_dir, "/") ? real_dir : "", base);
    if (n < 0 || n >= PATH_MAX) return errno = ENAMETOOLONG, -1;
    return 0;
}

int output_prepare(staged_output *out, const char *given, output_kind kind, const char *input, char *msg,
                   size_t msg_size) {
    memset(out, 0, sizeof *out);
    out->given = given;
    out->kind = kind;
    out->slot = -1;
    char ext[16];
    extension_of(given, ext, sizeof ext);
    if (!known_extension(kind, ext)) {
        const char *list = kind == OUTPUT_MESH ? ".ply, .obj, .off, .stl, .glb" : ".ply, .xyz";
        if (ext[0])
            say(msg, msg_size, "%s: GMPU_ERROR_UNSUPPORTED: %s: unsupported extension '.%s' (expected %s)",
                doing(kind), given, ext, list);
        else
            say(msg, msg_size, "%s: GMPU_ERROR_UNSUPPORTED: %s: no file extension (expected %s)", doing(kind),
                given, list);
        return 0;
    }
    if (resolve_target(given, out->target) != 0) return fail_errno(out, errno, msg, msg_size);
    struct stat st;
    if (stat(out->target, &st) == 0) {
        if (S_ISDIR(st.st_mode)) return fail_errno(out, EISDIR, msg, msg_size);
        if (!S_ISREG(st.st_mode)) {
            say(msg, msg_size, "%s: GMPU_ERROR_IO: %s: not a regular file", doing(kind), given);
            return 0;
        }
        struct stat in;
        if (input && stat(input, &in) == 0 && in.st_dev == st.st_dev && in.st_ino == st.st_ino) {
            say(msg, msg_size, "%s: GMPU_ERROR_INVALID_ARGUMENT: %s is the input file; choose another output",
                doing(kind), given);
            return 0;
        }
    }
    /* The staging file goes in the target's directory: it must take new files. */
    char dir[PATH_MAX];
    strcpy(dir, out->target);
    *strrchr(dir, '/') = '\0';
    if (access(dir[0] ? dir : "/", W_OK | X_OK) != 0) return fail_errno(out, errno, msg, msg_size);
    return 1;
}

int output_same_target(const staged_output *a, const staged_output *b) {
    if (!strcmp(a->target, b->target)) return 1;
    struct stat sa, sb; /* two names of one file (a hard link) */
    return stat(a->target, &sa) == 0 && stat(b->target, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

/* ---- staging files and the signal handler ----
 * The handler may only use async-signal-safe calls: it works from a table filled before
 * the files exist (directory descriptor, file name), never from malloc'd state. */

enum { SLOTS = 2 };

static struct {
    volatile sig_atomic_t active;
    int dir_fd;
    char name[NAME_MAX + 1];
    size_t name_len;
} g_staged[SLOTS];

/* The staging file and whatever the library is writing beside it (its temporary is the
 * staging name followed by ".tmp-"...). Async-signal-safe. */
static void remove_staged(int slot) {
    const int fd = g_staged[slot].dir_fd;
    const char *name = g_staged[slot].name;
    const size_t len = g_staged[slot].name_len;
    unlinkat(fd, name, 0);
    if (lseek(fd, 0, SEEK_SET) != 0) return;
    char buf[4096] __attribute__((aligned(8)));
    ssize_t n;
    while ((n = getdents64(fd, buf, sizeof buf)) > 0) {
        for (ssize_t at = 0; at < n;) {
            const struct dirent64 *e = (const struct dirent64 *)(buf + at);
            if (strncmp(e->d_name, name, len) == 0 && e->d_name[len] == '.') unlinkat(fd, e->d_name, 0);
            at += e->d_reclen;
        }
    }
}

static void on_fatal_signal(int sig) {
    const int saved = errno;
    for (int i = 0; i < SLOTS; ++i)
        if (g_staged[i].active) remove_staged(i);
    errno = saved;
    /* SA_RESETHAND restored the default action: die of the same signal once we return, so
     * the parent sees how the run ended. */
    raise(sig);
}

void output_install_signal_cleanup(void) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_fatal_signal;
    sa.sa_flags = SA_RESETHAND;
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT);
    sigaddset(&sa.sa_mask, SIGTERM);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

/* Blocks SIGINT / SIGTERM while the table and the files change together. */
static void block_signals(sigset_t *old) {
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigprocmask(SIG_BLOCK, &set, old);
}

/* Short enough that the library's temporary beside it ("<name>.tmp-gmpu-<pid>-<n>") still
 * fits in NAME_MAX, however long the target's name. */
enum { MAX_STAGED_BASE = 160 };

int output_stage(staged_output *out, char *msg, size_t msg_size) {
    int slot = -1;
    for (int i = 0; i < SLOTS; ++i)
        if (!g_staged[i].active && slot < 0) slot = i;
    if (slot < 0) {
        say(msg, msg_size, "%s: GMPU_ERROR_INTERNAL: too many outputs", doing(out->kind));
        return 0;
    }
    char dir[PATH_MAX];
    strcpy(dir, out->target);
    char *slash = strrchr(dir, '/');
    const char *base = out->target + (slash - dir) + 1;
    *slash = '\0';
    if (!dir[0]) strcpy(dir, "/");
    /* The extension the user wrote: it picks the format, even when a symlink's target is
     * named otherwise. */
    const char *dot = strrchr(out->given, '.');

    sigset_t old;
    block_signals(&old);
    int ok = 0, err = 0;
    const int dir_fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir_fd < 0) {
        err = errno;
    } else {
        /* A name no other file has (O_EXCL): leftovers of a killed run are skipped, never
         * reused or removed. */
        for (unsigned k = 0; k < 1000 && !ok; ++k) {
            int base_len = (int)strlen(base);
            if (base_len > MAX_STAGED_BASE) base_len = MAX_STAGED_BASE;
            snprintf(g_staged[slot].name, sizeof g_staged[slot].name, "%.*s.gmpu-%ld-%u%s", base_len, base,
                     (long)getpid(), k, dot);
            int fd = openat(dir_fd, g_staged[slot].name, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
            if (fd >= 0) {
                close(fd);
                ok = 1;
            } else if (errno != EEXIST) {
                err = errno;
                break;
            }
        }
        if (!ok && !err) err = EEXIST;
    }
    if (ok) {
        g_staged[slot].dir_fd = dir_fd;
        g_staged[slot].name_len = strlen(g_staged[slot].name);
        g_staged[slot].active = 1;
        out->slot = slot;
        snprintf(out->staging, sizeof out->staging, "%s/%s", strcmp(dir, "/") ? dir : "", g_staged[slot].name);
    } else if (dir_fd >= 0) {
        close(dir_fd);
    }
    sigprocmask(SIG_SETMASK, &old, NULL);
    return ok ? 1 : fail_errno(out, err, msg, msg_size);
}

static void unregister(staged_output *out) {
    if (out->slot < 0) return;
    g_staged[out->slot].active = 0;
    close(g_staged[out->slot].dir_fd);
    out->slot = -1;
    out->staging[0] = '\0';
}

int output_commit(staged_output *out, char *msg, size_t msg_size) {
    sigset_t old;
    block_signals(&old);
    int ok = rename(out->staging, out->target) == 0, err = errno;
    if (!ok) remove_staged(out->slot);
    unregister(out);
    sigprocmask(SIG_SETMASK, &old, NULL);
    return ok ? 1 : fail_errno(out, err, msg, msg_size);
}

void output_discard(staged_output *out) {
    if (out->slot < 0) return;
    sigset_t old;
    block_signals(&old);
    remove_staged(out->slot);
    unregister(out);
    sigprocmask(SIG_SETMASK, &old, NULL);
}
