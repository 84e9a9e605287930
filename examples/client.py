#!/usr/bin/env python3
"""A cranesim serve client using only the standard library (socket, struct).

It asks for control, works the jib out and back and prints, for every tenth
state frame, the paper's nine values (two strokes, four chamber pressures,
two valve openings, time), the crane tip in the world, the truck's roll and
pitch and the supply pressure. The wire format is docs/protocol.md (version 2).

    cranesim serve &                  # listens on 127.0.0.1:7575
    python3 examples/client.py 127.0.0.1 7575 150
"""
import math
import socket
import struct
import sys

MAGIC = 0x4D495343  # b"CSIM" little-endian
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


def main():
    host = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1"
    port = int(sys.argv[2]) if len(sys.argv) > 2 else 7575
    frames = int(sys.argv[3]) if len(sys.argv) > 3 else 150
    sock = socket.create_connection((host, port), timeout=10)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    send_frame(sock, CLIENT_HELLO, struct.pack("<IHB", MAGIC, 2, 1))  # version 2, control
    ftype, body = read_frame(sock)
    if ftype == ERROR:  # e.g. another protocol version: the server says which it speaks
        _, code, n = struct.unpack_from("<QHH", body)
        print("server says: " + body[12:12 + n].decode(errors="replace"), file=sys.stderr)
        return 1
    if ftype != SERVER_HELLO:
        print("no server hello (frame type %d)" % ftype, file=sys.stderr)
        return 1
    magic, version, role, lockstep, rate, jlen = struct.unpack_from("<IHBBdI", body)
    print("connected: protocol %d, role %s, %.0f frames/s" % (version, "control" if role else "watch", rate))
    print("%11s %10s %10s %10s %10s %10s %10s %7s %7s %23s %15s %9s" %
          ("t [s]", "x1 [mm]", "x2 [mm]", "p1A [MPa]", "p1B [MPa]", "p2A [MPa]", "p2B [MPa]", "u1", "u2",
           "tip x, y, z [m]", "roll, pitch [deg]", "p_s [MPa]"))
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
        x1, x2, p1a, p1b, p2a, p2b, u1, u2, t = struct.unpack_from("<9d", body)
        fseq, echo = struct.unpack_from("<QQ", body, 72)
        # After flags, slew, hook, load mass and attached: the tip (world,
        # m), the truck's roll and pitch (rad), the supply pressure (Pa).
        tx, ty, tz, roll, pitch, p_s = struct.unpack_from("<6d", body, 136)
        if last_frame and fseq > last_frame + 1:
            lost += fseq - last_frame - 1
        last_frame, last_echo = fseq, echo
        if got % 10 == 0:
            print("%11.3f %10.1f %10.1f %10.3f %10.3f %10.3f %10.3f %7.3f %7.3f %7.2f %7.2f %7.2f %7.2f %7.2f %9.3f" %
                  (t, x1 * 1e3, x2 * 1e3, p1a * 1e-6, p1b * 1e-6, p2a * 1e-6, p2b * 1e-6, u1, u2,
                   tx, ty, tz, math.degrees(roll), math.degrees(pitch), p_s * 1e-6))
        got += 1
        jib = 0.7 if got < frames // 2 else -0.7
        seq += 1
        send_frame(sock, COMMAND, struct.pack("<QB3d", seq, OP_VALVES, 0.0, jib, 0.0))
    print("%d frames, %d lost, last command echoed: %d of %d" % (got, lost, last_echo, seq))
    sock.close()
    return 0 if last_echo > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
