"""A hostile rig behind a real pseudo-terminal, written from docs/protocol.md alone (its own
COBS, CRC and frames: nothing of articula's), to try the host's bounds and deadlines.

    python tests/rigs/hostile.py MODE     prints "hostile rig at /dev/pts/N", serves until killed

It shakes hands as a motor rig (protocol 2, seven channels, a sample every 1000 µs), takes
every setting, answers GET with a body of the right length, and then, per MODE, misbehaves:

  flood            after START, TELEMETRY as fast as the line takes it, its time running on
                   past the run's end, never DONE
  flood-at-zero    the same, every sample at time 0
  running-forever  after START nothing but ACKs: STATUS says "running", 0 samples, forever
  short-telemetry  after START one TELEMETRY with a 2-byte body
  unknown-type     after START a frame of type 0x99
  long-info        its INFO is 300 bytes (the protocol's frames hold 254), its CRC right
"""

from __future__ import annotations

import os
import select
import struct
import sys
import threading
import tty

CHANNELS = ("i_ref", "A"), ("i_meas", "A"), ("i_fb", "A"), ("omega_meas", "rad/s"), \
    ("v1", "V"), ("duty1", "counts"), ("v2", "V")  # fmt: skip
MODES = ("flood", "flood-at-zero", "running-forever", "short-telemetry", "unknown-type",
         "long-info")  # fmt: skip
SETTINGS = {0x02: bytes(20), 0x03: bytes([4, 4]) + bytes(16)}  # SET_GAINS, SET_REFERENCE


def crc16(data: bytes) -> int:
    """CRC-16/CCITT-FALSE, bit by bit: poly 0x1021, init 0xFFFF, no reflection."""
    crc = 0xFFFF
    for byte in data:
        crc ^= byte << 8
        for _ in range(8):
            crc = (crc << 1) ^ 0x1021 if crc & 0x8000 else crc << 1
            crc &= 0xFFFF
    return crc


def stuff(data: bytes) -> bytes:
    """COBS, any length (a block every 254 bytes), without the delimiter."""
    out, block = bytearray(), bytearray()
    for byte in data:
        if byte == 0:
            out += bytes([len(block) + 1]) + block
            block.clear()
        else:
            block.append(byte)
            if len(block) == 254:
                out += b"\xff" + block
                block.clear()
    return bytes(out + bytes([len(block) + 1]) + block)


def unstuff(data: bytes) -> bytes:
    """COBS back (no checks: a hostile device does not care)."""
    out, at = bytearray(), 0
    while at < len(data):
        code = data[at]
        out += data[at + 1 : at + code]
        at += code
        if code < 0xFF and at < len(data):
            out.append(0)
    return bytes(out)


class Hostile:
    """The device on its pty; serve() answers until the pty closes.

    Args:
        mode: one of MODES.
    """

    def __init__(self, mode: str) -> None:
        self.mode = mode
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self.path = os.ttyname(self.slave)
        self.seq = 0
        self.running = False
        self.lock = threading.Lock()  # the flood's thread and the answers share the line

    def send(self, kind: int, body: bytes) -> None:
        """One frame: type, the device's seq, body, CRC; stuffed, delimited."""
        with self.lock:
            payload = struct.pack("<BH", kind, self.seq & 0xFFFF) + body
            self.seq += 1
            os.write(self.master, stuff(payload + struct.pack("<H", crc16(payload))) + b"\0")

    def info(self) -> bytes:
        """INFO's body: protocol 2, a motor rig, firmware 0.2.0, 1000 µs, the channels."""
        body = struct.pack("<BBBBBIB", 2, 3, 0, 2, 0, 1000, len(CHANNELS))
        for pair in CHANNELS:
            for text in pair:
                body += bytes([len(text)]) + text.encode()
        if self.mode == "long-info":  # a last text of 226 characters: a frame of 300 bytes
            body = body[:-7] + bytes([226]) + b"x" * 226
        return body + b"\0"  # reset: power-on

    def answer(self, kind: int, seq: int, body: bytes) -> None:
        """A command from the host."""
        ack = struct.pack("<H", seq)
        if kind == 0x01:
            self.send(0x81, self.info())
        elif kind == 0x09:
            self.send(0x82, ack + struct.pack("<BIHB", self.running, 0, 0, 0))
        elif kind == 0x0A:
            self.send(0x82, ack + SETTINGS.get(body[0], b""))
        else:
            self.send(0x82, ack)
        if kind == 0x04:
            self.running = True
            self.misbehave()

    def misbehave(self) -> None:
        """What MODE does once a run starts."""
        if self.mode == "short-telemetry":
            self.send(0x84, b"\x01\x02")
        elif self.mode == "unknown-type":
            self.send(0x99, b"")
        elif self.mode.startswith("flood"):
            threading.Thread(target=self.flood, daemon=True).start()

    def flood(self) -> None:
        """TELEMETRY without end."""
        micros = 0
        while True:
            body = struct.pack("<I", micros) + struct.pack("<7f", *range(7))
            try:
                self.send(0x84, body)
            except OSError:
                return
            if self.mode == "flood":
                micros = (micros + 1000) & 0xFFFFFFFF

    def serve(self) -> None:
        """Read commands and answer them."""
        pending = b""
        while True:
            select.select([self.master], [], [])
            try:
                pending += os.read(self.master, 4096)
            except OSError:
                return
            *frames, pending = pending.split(b"\0")
            for raw in filter(None, frames):
                payload = unstuff(raw)
                if len(payload) >= 5:
                    kind, seq = struct.unpack_from("<BH", payload)
                    self.answer(kind, seq, payload[3:-2])


if __name__ == "__main__":
    device = Hostile(sys.argv[1])
    print(f"hostile rig at {device.path}", flush=True)
    device.serve()
