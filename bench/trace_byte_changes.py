#!/usr/bin/env python3
"""Random single-byte changes of a trace file with its header's CRC-32 made to match, each read by
`calligraphy trace FILE --csv /dev/null`: counts the reads (exit 0), the refusals (exit 1) and anything else
(a crash, a hang), and keeps each file of the last kind beside the trace as crash-SEED-N.trace.h5.
Not a test (docs/testing.md): HDF5 1.10 may still crash on a structure made to pass the CRC-32.

    python3 bench/trace_byte_changes.py TRACE.trace.h5 build/bin/calligraphy 1500 1
"""
import pathlib
import random
import subprocess
import sys
import zlib

USER_BLOCK_BYTES = 512


def main() -> int:
    if len(sys.argv) != 5:
        print(__doc__, file=sys.stderr)
        return 2
    source, cli, count, seed = pathlib.Path(sys.argv[1]), sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    rng = random.Random(seed)
    original = source.read_bytes()[USER_BLOCK_BYTES:]
    changed_file = source.with_name("changed.trace.h5")
    counts: dict[str, int] = {}
    for i in range(count):
        body = bytearray(original)
        position = rng.randrange(len(body))
        body[position] = rng.randrange(256)
        head = f"calligraphy-trace\nversion 1\nbytes {len(body)}\ncrc32 {zlib.crc32(body):08x}\n".encode()
        data = head + b"\0" * (USER_BLOCK_BYTES - len(head)) + bytes(body)
        changed_file.write_bytes(data)
        try:
            status = subprocess.run([cli, "trace", str(changed_file), "--csv", "/dev/null"], capture_output=True,
                                    timeout=60).returncode
            kind = {0: "read", 1: "refused"}.get(status, f"status {status}")
        except subprocess.TimeoutExpired:
            kind = "hang"
        counts[kind] = counts.get(kind, 0) + 1
        if kind not in ("read", "refused"):
            source.with_name(f"crash-{seed}-{i}.trace.h5").write_bytes(data)
    changed_file.unlink(missing_ok=True)
    print(", ".join(f"{kind}: {n}" for kind, n in sorted(counts.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
