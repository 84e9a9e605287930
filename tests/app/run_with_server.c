// run_with_server.c: run a client command against a real `cranesim serve`:
// start the server on a free port, run the command with each "{PORT}" in
// its arguments (alone or inside one, 127.0.0.1:{PORT}) replaced by that port, then SIGINT the server. Passes when
// the client exits 0 and the server ends cleanly (exit 0) on SIGINT.
//   run_with_server [SERVE ARGS...] -- CLIENT ARGS...
#define _DEFAULT_SOURCE // usleep, in serve_util.h
#include "serve_util.h"

int main(int argc, char** argv) {
    int dd = 1;
    while (dd < argc && strcmp(argv[dd], "--")) ++dd;
    if (dd >= argc - 1) {
        fprintf(stderr, "usage: run_with_server [SERVE ARGS...] -- CLIENT ARGS...\n");
        return 2;
    }
    const char* sargs[48] = {0};
    for (int k = 1; k < dd && k < 47; ++k) sargs[k - 1] = argv[k];
    served sv;
    if (serve_start(&sv, NULL, sargs)) {
        fprintf(stderr, "run_with_server: the server did not start\n");
        return 1;
    }
    char port[16];
    snprintf(port, sizeof port, "%d", sv.port);
    char* cargs[64];
    static char sub[64][512];
    int n = 0;
    for (int k = dd + 1; k < argc && n < 63; ++k) { // "{PORT}" anywhere in an argument
        const char* at = strstr(argv[k], "{PORT}");
        if (at) {
            snprintf(sub[n], sizeof sub[n], "%.*s%s%s", (int)(at - argv[k]), argv[k], port, at + 6);
            cargs[n] = sub[n];
        } else {
            cargs[n] = argv[k];
        }
        ++n;
    }
    cargs[n] = NULL;
    pid_t pid = fork();
    if (pid == 0) {
        execvp(cargs[0], cargs);
        _exit(127);
    }
    int st = 0;
    waitpid(pid, &st, 0);
    const int client = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    const int server = serve_stop(&sv);
    printf("run_with_server: client exit %d, server exit %d after SIGINT\n", client, server);
    return client == 0 && server == 0 ? 0 : 1;
}
