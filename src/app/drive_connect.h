// drive_connect.h: what both views of `drive --connect` (drive_connect.c
// headless, drive_connect_window.c in the window) read from a version-3
// server's hello: the functions the operator commands, in the order of the
// VALVES openings (docs/protocol.md).
#ifndef DRIVE_CONNECT_H
#define DRIVE_CONNECT_H

#include "protocol.h"

#include <stddef.h>

#define DC_FN_NAME 48

typedef struct dc_functions {
    int n;                                // 1..PROTO_MAX_FN
    char name[PROTO_MAX_FN][DC_FN_NAME];  // "lift", "jib", "ext", "slew"
    int cyl[PROTO_MAX_FN];                // the first cylinder record each drives, -1 none
    int ncyl;                             // the hello's cylinder records
    char cyl_name[PROTO_MAX_CYL][DC_FN_NAME];
    int cyl_fn[PROTO_MAX_CYL];            // the function each cylinder record belongs to, -1 none
} dc_functions;

/// The hello's "functions" (and "cylinders") into f. 0, or -1 with one line
/// in err: no JSON, no functions, more than PROTO_MAX_FN, a name missing or
/// too long.
int dc_hello_functions(const char* json, size_t len, dc_functions* f, char* err, size_t errsz);

#endif
