// app_output.c: output files: checked before a run, written to a temporary
// file and renamed over the final name when done (app_out), folders made.
// realpath (X/Open) for app_out_open.
#define _XOPEN_SOURCE 700
#include "app.h"
#include "engine.h"
#include "world_desc.h"

#include <ctype.h>
#include <limits.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <dirent.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

int app_fclose_checked(FILE* f, int first) {
    int e = first;
    const int flagged = ferror(f);
    errno = 0;
    if (fflush(f) != 0 && !e) e = errno ? errno : EIO;
    errno = 0;
    if (fclose(f) != 0 && !e) e = errno ? errno : EIO;
    if (flagged && !e) e = EIO;
    return e;
}

// The temporary files of an output are named ".NAME.cranesim-HOST-PID.XXXXXX"
// in NAME's folder: the host and process that write it. A run killed with
// SIGKILL (or a crash) cannot remove its own; the next run that writes NAME
// removes those of this host whose process is gone, and says so. A file
// whose process still runs (another cranesim writing NAME) is never touched,
// nor one of another host (a shared folder: its pids mean nothing here), nor
// a name of another form (the ".NAME.XXXXXX" of older versions: whose it is
// cannot be told).
static void temp_prefix(char* out, size_t n, const char* base) {
    char host[65] = "";
    if (gethostname(host, sizeof host - 1)) snprintf(host, sizeof host, "localhost");
    host[sizeof host - 1] = 0;
    for (char* c = host; *c; ++c)
        if (*c == '/' || *c == '-') *c = '_'; // the pid follows the last '-'
    snprintf(out, n, ".%s.cranesim-%.32s-", base, host);
}

static void remove_stale_temps(const char* dir, const char* base) {
    char pre[400];
    temp_prefix(pre, sizeof pre, base);
    const size_t lp = strlen(pre);
    DIR* d = opendir(dir[0] ? dir : ".");
    if (!d) return;
    for (struct dirent* e; (e = readdir(d));) {
        const char* nm = e->d_name;
        if (strncmp(nm, pre, lp)) continue;
        // PID, then "." and mkstemp's six characters, nothing else.
        const char* p = nm + lp;
        char* end;
        errno = 0;
        const long pid = strtol(p, &end, 10);
        if (end == p || !isdigit((unsigned char)*p) || errno || pid <= 0 || *end != '.' || strlen(end + 1) != 6)
            continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue; // alive (or not ours to ask): keep it
        char full[PATH_MAX + 300];
        snprintf(full, sizeof full, "%s%s", dir, nm);
        struct stat st;
        if (lstat(full, &st) || !S_ISREG(st.st_mode) || st.st_uid != getuid()) continue;
        if (unlink(full) == 0)
            fprintf(stderr, "note: removed %s, the temporary file of an output of cranesim process %ld, which "
                            "ended without finishing it (killed)\n",
                    full, pid);
    }
    closedir(d);
}

FILE* app_out_open(app_out* o, const char* path, const char* mode) {
    memset(o, 0, sizeof *o);
    struct stat st;
    const bool exists = stat(path, &st) == 0;
    if (exists && !S_ISREG(st.st_mode)) { // a device or a pipe: in place
        snprintf(o->path, sizeof o->path, "%s", path);
        o->f = fopen(path, mode);
        return o->f;
    }
    // Through a symlink to the file it names: renaming over the link itself
    // would replace the link with a file.
    char real[PATH_MAX];
    const char* target = exists && realpath(path, real) ? real : path;
    if (strlen(target) >= sizeof o->path) {
        errno = ENAMETOOLONG;
        return NULL;
    }
    memcpy(o->path, target, strlen(target) + 1); // fits: checked above
    const char* slash = strrchr(o->path, '/');
    const int dl = slash ? (int)(slash - o->path + 1) : 0;
    char dir[PATH_MAX], pre[400];
    snprintf(dir, sizeof dir, "%.*s", dl, o->path);
    remove_stale_temps(dir, o->path + dl);
    temp_prefix(pre, sizeof pre, o->path + dl);
    if ((size_t)snprintf(o->tmp, sizeof o->tmp, "%s%s%ld.XXXXXX", dir, pre, (long)getpid()) >= sizeof o->tmp ||
        strlen(pre) + 30 >= NAME_MAX) {
        // A name too long to add the host and pid: the short form, which a
        // later run cannot tell from another's and leaves alone after a kill.
        snprintf(o->tmp, sizeof o->tmp, "%.*s.%s.XXXXXX", dl, o->path, o->path + dl);
    }
    const int fd = mkstemp(o->tmp);
    if (fd < 0) {
        // A folder we may not create files in, holding a file we may write:
        // write it in place, as before (app_check_output let it through).
        const int e = errno;
        o->tmp[0] = 0;
        if (exists && access(o->path, W_OK) == 0) {
            o->f = fopen(o->path, mode);
            return o->f;
        }
        errno = e;
        return NULL;
    }
    // mkstemp makes it 0600: give it the mode the old file had, or a new
    // file's (0666 less the umask).
    mode_t mode_bits;
    if (exists) {
        mode_bits = st.st_mode & 07777;
    } else {
        const mode_t um = umask(0);
        umask(um);
        mode_bits = 0666 & ~um;
    }
    if (fchmod(fd, mode_bits)) { /* the data matters more than the mode */
    }
    o->f = fdopen(fd, mode);
    if (!o->f) {
        const int e = errno;
        close(fd);
        unlink(o->tmp);
        o->tmp[0] = 0;
        errno = e;
    }
    return o->f;
}

int app_out_close(app_out* o, int first, bool keep) {
    int e = first;
    if (o->f) e = app_fclose_checked(o->f, first);
    o->f = NULL;
    if (o->tmp[0]) {
        if (keep && !e && rename(o->tmp, o->path)) e = errno;
        if (!keep || e) unlink(o->tmp);
        o->tmp[0] = 0;
    }
    return e;
}

int app_out_commit_signal(const app_out* o) { return o->tmp[0] ? rename(o->tmp, o->path) : 0; }

int app_check_output(const char* cmd, const char* opt, const char* path, const char* ext) {
    if (!*path) {
        fprintf(stderr, "cranesim %s: %s: empty file name\n", cmd, opt);
        return -1;
    }
    struct stat st;
    const bool exists = stat(path, &st) == 0;
    if (exists && S_ISDIR(st.st_mode)) {
        fprintf(stderr, "cranesim %s: %s %s: is a directory\n", cmd, opt, path);
        return -1;
    }
    // A device or a pipe (/dev/stdout, /dev/null) takes whatever is written;
    // a file named x.jpg holding PNG data would mislead every viewer.
    const size_t L = strlen(path), le = ext ? strlen(ext) : 0;
    if (ext && !(exists && !S_ISREG(st.st_mode)) && (L <= le || strcasecmp(path + L - le, ext))) {
        fprintf(stderr, "cranesim %s: %s %s: the file is written as %s, so its name must end in %s\n", cmd, opt,
                path, ext + 1, ext);
        return -1;
    }
    if (exists) {
        if (access(path, W_OK)) {
            fprintf(stderr, "cranesim %s: %s %s: cannot write: %s\n", cmd, opt, path, strerror(errno));
            return -1;
        }
        return 0;
    }
    char dir[1024];
    const char* slash = strrchr(path, '/');
    if (!slash) snprintf(dir, sizeof dir, ".");
    else if (slash == path) snprintf(dir, sizeof dir, "/");
    else snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    if (stat(dir, &st) || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "cranesim %s: %s %s: no directory %s\n", cmd, opt, path, dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK)) {
        fprintf(stderr, "cranesim %s: %s %s: cannot create a file in %s: %s\n", cmd, opt, path, dir,
                strerror(errno));
        return -1;
    }
    return 0;
}

// The file path names, as "realpath(dirname)/basename" (the folder must
// exist: app_check_output has checked it); false if it cannot be resolved.
static bool resolved_name(const char* path, char* out, size_t n) {
    char dir[PATH_MAX], real[PATH_MAX];
    const char* slash = strrchr(path, '/');
    const char* base = slash ? slash + 1 : path;
    if (!slash) snprintf(dir, sizeof dir, ".");
    else if (slash == path) snprintf(dir, sizeof dir, "/");
    else snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    if (!realpath(dir, real)) return false;
    return (size_t)snprintf(out, n, "%s/%s", real, base) < n;
}

int app_check_distinct(const char* cmd, const char* const* opts, const char* const* paths, int n) {
    for (int i = 0; i < n; ++i) {
        for (int j = i + 1; j < n; ++j) {
            if (!paths[i] || !paths[j]) continue;
            struct stat si, sj;
            const bool ei = stat(paths[i], &si) == 0, ej = stat(paths[j], &sj) == 0;
            bool same;
            if (ei && ej) {
                // Devices and pipes (/dev/null twice) take any number of writers.
                same = si.st_dev == sj.st_dev && si.st_ino == sj.st_ino && S_ISREG(si.st_mode);
            } else if (ei != ej) {
                same = false; // one name exists, the other does not: two files
            } else {
                char a[2 * PATH_MAX], b[2 * PATH_MAX];
                same = resolved_name(paths[i], a, sizeof a) && resolved_name(paths[j], b, sizeof b) && !strcmp(a, b);
            }
            if (same) {
                fprintf(stderr, "cranesim %s: %s %s and %s %s name the same file: each output needs its own\n", cmd,
                        opts[i], paths[i], opts[j], paths[j]);
                return -1;
            }
        }
    }
    return 0;
}

int app_make_dir(const char* cmd, const char* opt, const char* dir) {
    char buf[1024];
    if (!*dir) {
        fprintf(stderr, "cranesim %s: %s: empty directory name\n", cmd, opt);
        return -1;
    }
    if (strlen(dir) >= sizeof buf) {
        fprintf(stderr, "cranesim %s: %s: directory name too long\n", cmd, opt);
        return -1;
    }
    snprintf(buf, sizeof buf, "%s", dir);
    // Only the last component is made: a missing parent is more likely a
    // typo in the path than a tree to create (as for an output file's folder).
    size_t L = strlen(buf);
    while (L > 1 && buf[L - 1] == '/') buf[--L] = 0;
    struct stat st;
    if (stat(buf, &st) != 0) {
        char parent[1024];
        const char* slash = strrchr(buf, '/');
        if (!slash) snprintf(parent, sizeof parent, ".");
        else if (slash == buf) snprintf(parent, sizeof parent, "/");
        else snprintf(parent, sizeof parent, "%.*s", (int)(slash - buf), buf);
        struct stat sp;
        if (stat(parent, &sp) || !S_ISDIR(sp.st_mode)) {
            fprintf(stderr, "cranesim %s: %s %s: no directory %s\n", cmd, opt, dir, parent);
            return -1;
        }
        if (mkdir(buf, 0755) && errno != EEXIST) {
            fprintf(stderr, "cranesim %s: %s %s: cannot create it: %s\n", cmd, opt, dir, strerror(errno));
            return -1;
        }
    }
    if (stat(buf, &st) || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "cranesim %s: %s %s: exists and is not a directory\n", cmd, opt, dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK)) {
        fprintf(stderr, "cranesim %s: %s %s: cannot write into it: %s\n", cmd, opt, dir, strerror(errno));
        return -1;
    }
    return 0;
}
