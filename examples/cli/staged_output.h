/* The CLI's output files: checked before any work, written under a name of our own beside
 * the target, and moved into place only when every output of the run is complete.
 *
 * Why the CLI stages its outputs itself rather than rely on the library's atomic write
 * alone: a run may write two files (the mesh and the oriented points). Each write is atomic,
 * but the pair is not: if the second fails, the first must not have replaced anything yet.
 * So both are written to staging files (created by this run with O_EXCL, so they can never
 * be someone else's file) and renamed over their targets at the end.
 *
 * A symlink as target is written through: the file it points to is replaced, the link
 * stays. SIGINT / SIGTERM remove every staging file (and the library's temporary beside it)
 * before the process dies of the signal. */
#pragma once

#include <limits.h>
#include <stddef.h>

typedef enum { OUTPUT_MESH, OUTPUT_POINTS } output_kind;

typedef struct {
    const char *given;         /* the path as the user wrote it (for messages) */
    output_kind kind;
    char target[PATH_MAX];     /* where the bytes land: symlinks followed, directory absolute */
    char staging[PATH_MAX];    /* "" until staged */
    int slot;                  /* in the signal handler's table; -1 when not registered */
} staged_output;

/* Checks `given` as an output of `kind` before any work: a known extension, an existing
 * writable directory, not a directory or special file, not the file at `input` (same
 * device and inode). Fills out->target. On failure writes the one-line message (without
 * the program name) to msg and returns 0. */
int output_prepare(staged_output *out, const char *given, output_kind kind, const char *input, char *msg,
                   size_t msg_size);

/* Whether two prepared outputs land in the same file. */
int output_same_target(const staged_output *a, const staged_output *b);

/* Installs the SIGINT / SIGTERM handler that removes staging files. */
void output_install_signal_cleanup(void);

/* Creates the staging file beside the target (a fresh name this run owns) and registers it
 * for the signal handler. 0 with msg on failure. */
int output_stage(staged_output *out, char *msg, size_t msg_size);

/* Renames the staging file over the target. 0 with msg on failure (the staging file is then
 * removed). */
int output_commit(staged_output *out, char *msg, size_t msg_size);

/* Removes the staging file, if any (and its registration). The target is never touched. */
void output_discard(staged_output *out);
