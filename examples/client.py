#!/usr/bin/env python3
"""A cranesim serve client using only the standard library (socket, struct, json).

It asks for control and prints the functions the server's hello lists (with
the actuators each drives), then for every tenth state frame the time, the
crane tip in the world, the truck's roll and pitch and the supply pressure,
and every function's values: its first actuator's stroke and chamber
pressures, its spool opening and its command. It works the jib (else the
second function) out and back, one opening per function. The wire format
is docs/protocol.md (version 3).

    cranesim serve &                  # listens on 127.0.0.1:7575
    python3 examples/client.py 127.0.0.1 7575 150
"""
import json
import math
import socket
import struct
import sys

MAGIC = 0x4D495343  # b"CSIM" little-endian
VERSION = 3
CLIENT_HELLO, SERVER_HELLO, STATE, COMMAND, ERROR, NOTICE = 1, 2, 3, 4, 5, 6
OP_VALVES = 1


def read_exact(sock, n):
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ConnectionError("the link closed")
        data += chunk
    return data


def read_frame(sock):
    (length,) = struct.unpack("<I", read_exact(sock, 4))
    if length == 0 or length > (1 << 20):
        raise ValueError("bad frame length %d" % length)
    body = read_exact(sock, length)
    return body[0], body[1:]


def send_frame(sock, ftype, payload):
    sock.sendall(struct.pack("<IB", len(payload) + 1, ftype) + payload)


def parse_state(b):
    """The state frame's payload (after the type byte) as a dict."""
    s = {}
    s["nine"] = struct.unpack_from("<9d", b, 0)
    s["seq"], s["cmd_seq"] = struct.unpack_from("<QQ", b, 72)
    # After flags, slew, hook, load mass and attached: the tip (world, m),
    # the truck's roll and pitch (rad), the supply pressure (Pa).
    s["tip"] = struct.unpack_from("<3d", b, 136)
    s["roll"], s["pitch"], s["p_supply"] = struct.unpack_from("<3d", b, 160)
    o = 200
    npad = b[o]
    o += 1 + 8 * npad
    (nrow,) = struct.unpack_from("<H", b, o)
    s["row"] = struct.unpack_from("<%dd" % nrow, b, o + 2)
    o += 2 + 8 * nrow
    (nbody,) = struct.unpack_from("<H", b, o)
    o += 2 + 96 * nbody
    ncyl = b[o]
    o += 1
    s["cyl"] = []
    for _ in range(ncyl):  # base 3, rod end 3, x, pA, pB, u, u_cmd, force, v; status bits
        s["cyl"].append(struct.unpack_from("<13d", b, o))
        o += 13 * 8 + 1
    nrope = b[o]
    o += 1 + 24 * nrope
    nrelief = b[o]
    o += 1
    for _ in range(nrelief):
        o += 3 + b[o + 2]
    nfn = b[o]
    o += 1
    s["fn"] = [struct.unpack_from("<2d", b, o + 16 * k) for k in range(nfn)]  # command, spool
    o += 16 * nfn
    if o != len(b):
        raise ValueError("state frame: %d bytes after its fields" % (len(b) - o))
    return s


def main():
    host = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1"
    port = int(sys.argv[2]) if len(sys.argv) > 2 else 7575
    frames = int(sys.argv[3]) if len(sys.argv) > 3 else 150
    sock = socket.create_connection((host, port), timeout=10)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    send_frame(sock, CLIENT_HELLO, struct.pack("<IHB", MAGIC, VERSION, 1))  # control
    ftype, body = read_frame(sock)
    if ftype == ERROR:  # e.g. another protocol version: the server says which it speaks
        _, code, n = struct.unpack_from("<QHH", body)
        print("server says: " + body[12:12 + n].decode(errors="replace"), file=sys.stderr)
        return 1
    if ftype != SERVER_HELLO:
        print("no server hello (frame type %d)" % ftype, file=sys.stderr)
        return 1
    magic, version, role, lockstep, rate, jlen = struct.unpack_from("<IHBBdI", body)
    desc = json.loads(body[20:20 + jlen])
    fns = desc["functions"]
    print("connected: protocol %d, role %s, %.0f frames/s, %s" %
          (version, "control" if role else "watch", rate, desc["model"]))
    print("%d functions (VALVES takes one opening each, in this order):" % len(fns))
    for k, f in enumerate(fns):
        acts = ", ".join("%s (cylinder %d: stroke %s, pA %s, pB %s, force %s)" %
                         (a["name"], a["cylinder"], a["units"]["stroke"], a["units"]["pA"], a["units"]["pB"],
                          a["units"]["force"]) for a in f["actuators"])
        print("  %d %-10s command [%s] in [%g, %g]: %s" %
              (k, f["name"], f["unit"], f["range"][0], f["range"][1], acts or "no actuator"))
    names = [f["name"] for f in fns]
    worked = names.index("jib") if "jib" in names else min(1, len(names) - 1)
    seq = got = lost = 0
    last_frame = last_echo = 0
    while got < frames:
        ftype, body = read_frame(sock)
        if ftype in (ERROR, NOTICE):
            _, code, n = struct.unpack_from("<QHH", body)
            print("server says: " + body[12:12 + n].decode(errors="replace"), file=sys.stderr)
            if ftype == ERROR:
                return 1
            continue
        if ftype != STATE:
            continue
        s = parse_state(body)
        if last_frame and s["seq"] > last_frame + 1:
            lost += s["seq"] - last_frame - 1
        last_frame, last_echo = s["seq"], s["cmd_seq"]
        if got % 10 == 0:
            t = s["nine"][8]
            print("t %.3f s: tip %.2f %.2f %.2f m, roll %.2f pitch %.2f deg, p_s %.3f MPa" %
                  (t, s["tip"][0], s["tip"][1], s["tip"][2], math.degrees(s["roll"]), math.degrees(s["pitch"]),
                   s["p_supply"] * 1e-6))
            for k, f in enumerate(fns):
                cmd, spool = s["fn"][k]
                if f["actuators"]:
                    c = s["cyl"][f["actuators"][0]["cylinder"]]
                    print("  %-10s stroke %8.1f mm  pA %8.3f MPa  pB %8.3f MPa  u %+.3f  command %+.3f" %
                          (f["name"], c[6] * 1e3, c[7] * 1e-6, c[8] * 1e-6, spool, cmd))
                else:
                    print("  %-10s u %+.3f  command %+.3f" % (f["name"], spool, cmd))
        got += 1
        u = [0.0] * len(fns)
        u[worked] = 0.7 if got < frames // 2 else -0.7
        seq += 1
        send_frame(sock, COMMAND, struct.pack("<QBB%dd" % len(u), seq, OP_VALVES, len(u), *u))
    print("%d frames, %d lost, last command echoed: %d of %d" % (got, lost, last_echo, seq))
    sock.close()
    return 0 if last_echo > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
