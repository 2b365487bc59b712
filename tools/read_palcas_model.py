#!/usr/bin/env python3
"""Read a PALCAS model or checkpoint file (format: src/doc/learning.md) with numpy.

Prints the layout and, per tensor, its shape and statistics. Verifies the magic bytes,
version, trailing FNV-1a 64 checksum and the layout checksum, like the C++ reader.

  tools/read_palcas_model.py FILE [--dump DIR]   (--dump writes one .npy per tensor)
"""
import argparse
import re
import struct
import sys

import numpy as np

MAGIC = b"PALCASNN"
VERSION = 1
KINDS = {1: "model", 2: "agent checkpoint"}


def fnv1a64(data):
    h = 14695981039346656037
    for b in data:
        h = ((h ^ b) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h


class Reader:
    def __init__(self, data, path):
        self.data, self.path, self.off = data, path, 0

    def take(self, n, what):
        if self.off + n > len(self.data):
            sys.exit(f"{self.path} is truncated: {what} needs {n} bytes at offset {self.off}")
        out = self.data[self.off:self.off + n]
        self.off += n
        return out

    def u32(self):
        return struct.unpack("<I", self.take(4, "u32"))[0]

    def u64(self):
        return struct.unpack("<Q", self.take(8, "u64"))[0]

    def string(self):
        return self.take(self.u64(), "string")

    def floats(self):
        n = self.u64()
        return np.frombuffer(self.take(4 * n, "float array"), dtype="<f4")


def tensors_of(layout):
    """(name, shape, is_buffer) per tensor of one network, in getState() order:
    every layer's parameters, then every layer's buffers."""
    params, buffers = [], []
    for i, layer in enumerate(layout.split(";")):
        m = re.fullmatch(r"(\w+)\(([^)]*)\)", layer)
        if not m:
            sys.exit(f"unknown layer description {layer!r}")
        kind, args = m.group(1), m.group(2).split(",")
        if kind == "Linear":
            n_in, n_out = int(args[0]), int(args[1])
            params += [(f"{i}.Linear.weight", (n_out, n_in)), (f"{i}.Linear.bias", (n_out,))]
        elif kind == "BatchNorm1d":
            n = int(args[0])
            params += [(f"{i}.BatchNorm1d.gamma", (n,)), (f"{i}.BatchNorm1d.beta", (n,))]
            buffers += [(f"{i}.BatchNorm1d.running_mean", (n,)),
                        (f"{i}.BatchNorm1d.running_var", (n,))]
    return params + buffers


def networks_of(layout):
    """[(network name, layer layout)]: an agent layout 'palcas-pdqn/1 p-dqn mu[...] q[...]'
    holds two networks; anything else is one network."""
    found = re.findall(r"(\w+)\[([^\]]*)\]", layout)
    return found if found else [("net", layout)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file")
    ap.add_argument("--dump", help="directory for one .npy file per tensor")
    args = ap.parse_args()
    data = open(args.file, "rb").read()
    if data[:8] != MAGIC:
        sys.exit(f"{args.file} is not a PALCAS model file (bad magic bytes)")
    r = Reader(data, args.file)
    r.take(8, "magic")
    version = r.u32()
    if version != VERSION:
        sys.exit(f"{args.file} has format version {version}, this reader reads {VERSION}")
    kind = r.u32()
    layout = r.string().decode()
    layout_checksum = r.u64()
    values = r.floats()
    extra = r.string()
    body = r.off
    stored = r.u64()
    if stored != fnv1a64(data[:body]):
        sys.exit(f"{args.file} has a bad checksum (file corrupted)")
    if layout_checksum != fnv1a64(layout.encode()):
        sys.exit(f"{args.file}: layout checksum does not match its layout string")
    print(f"file: {args.file}  kind: {KINDS.get(kind, kind)}  version: {version}")
    print(f"layout: {layout}")
    print(f"layout checksum: {layout_checksum:#018x}  values: {values.size}  "
          f"extra bytes: {len(extra)}")
    off = 0
    print(f"{'tensor':44s} {'shape':>12s} {'mean':>10s} {'std':>10s} {'min':>10s} {'max':>10s}")
    for net, net_layout in networks_of(layout):
        for name, shape in tensors_of(net_layout):
            n = int(np.prod(shape))
            t = values[off:off + n]
            if t.size != n:
                sys.exit(f"{args.file}: values end inside tensor {net}.{name}")
            # Eigen stores matrices column-major.
            t = t.reshape(shape, order="F")
            off += n
            print(f"{net + '.' + name:44s} {str(shape):>12s} {t.mean():10.4f} {t.std():10.4f} "
                  f"{t.min():10.4f} {t.max():10.4f}")
            if args.dump:
                import os
                os.makedirs(args.dump, exist_ok=True)
                np.save(os.path.join(args.dump, f"{net}.{name}.npy"), t)
    if off != values.size:
        sys.exit(f"{args.file}: {values.size - off} values left over after the layout's tensors")


if __name__ == "__main__":
    main()
