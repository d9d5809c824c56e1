#!/usr/bin/env python3
"""checkpoint_rows.py CHECKPOINT.bin HEADER.csv > runs.csv: the runs an interrupted
`gapfleet study traffic` had finished, from its checkpoint (24-byte header, then per run a
u32 little-endian length and the MessagePack of [run index, row]), as runs.csv rows under
HEADER.csv's first line, in run order. Needs the msgpack package."""
import msgpack, struct, sys, csv
data = open(sys.argv[1], 'rb').read()
header = open(sys.argv[2]).readline().strip().split(',') if len(sys.argv) > 2 else None
off = 24
rows = []
while off + 4 <= len(data):
    (n,) = struct.unpack_from('<I', data, off); off += 4
    if off + n > len(data): break
    idx, row = msgpack.unpackb(data[off:off+n], raw=False, strict_map_key=False); off += n
    rows.append((idx, row))
print(len(rows), 'runs', file=sys.stderr)
if header:
    w = csv.writer(sys.stdout, lineterminator='\n')
    w.writerow(header)
    for idx, row in sorted(rows, key=lambda r: r[0]):
        w.writerow(['true' if v is True else 'false' if v is False else repr(v) if isinstance(v, float) else v for v in row])
