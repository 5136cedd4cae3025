"""What checking files costs: part files read in a child process first, and the checks of a resume.

A part file is read by Netgen / OpenCASCADE in a child process (:func:`ngwear.model.part_files.describe`) before
this process reads it, so that a damaged file cannot crash the run.  Per part: the child (process start,
imports, the read), the same read in this process (what ``describe`` did before), and what the run does
with the part anyway: meshing it (STEP, built-in pad) or reading it (``.vol``).  Parts: ``cad_pad.step``
(maxh 0.005), the brake pad at maxh 0.002 (32k DOFs) as a ``.vol`` part, and the paper strip's ``.vol``.
A resume hashes ``mesh.vol`` (SHA-256) and reads the counted rows once for their CRC-32: timed on the brake
pad's ``mesh.vol`` and on the rows of 20 000 of its steps (2.1 GB; page cache warm).  Medians of ``--reps``.

    .venv/bin/python benchmarks/file_checks.py [--quick] [--reps 5]
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import common as C

PAD_MAXH, ROW_BYTES, STEPS = 0.002, 8 * (1 + 7 * 1889), 20000    # 1 889 contact points: w, u_ν, p, λ, forces (3)


def part_rows(name: str, path: Path, kind: str, reps: int, build) -> dict:
    """Child vs in-process read of a part file, and the meshing (or reading) the run does anyway."""
    from ngwear.model import part_files

    stat = path.stat()
    child = [C.timed(part_files._describe.__wrapped__, str(path), kind, stat.st_size, stat.st_mtime_ns)[0]
             for _ in range(reps)]
    here = [C.timed(part_files._read, str(path), kind)[0] for _ in range(reps)]
    work = [C.timed(build)[0] for _ in range(reps)]
    child_s, here_s, work_s = C.median(child), C.median(here), C.median(work)
    return {"part": name, "size_mb": stat.st_size / 1e6, "child_s": child_s, "in_process_s": here_s,
            "extra_s": child_s - here_s, "mesh_or_read_s": work_s, "extra_share": (child_s - here_s) / work_s}


def main():
    args = C.parser(__doc__.splitlines()[0]).parse_args()
    import ngwear
    from ngwear.model import part_files
    from ngwear.model.scene_mesh import build_mesh
    from ngwear.results.folder import _digest
    from ngwear.results.recording import History

    rows = []
    cad_scene = ngwear.load_scene(C.ROOT / "geometries" / "cad_pad.toml")
    rows.append(part_rows("cad_pad.step (mesh 0.005)", Path(cad_scene.geometry.file), "step", args.reps,
                          lambda: build_mesh(cad_scene, use_cache=False)))
    pad = ngwear.load_scene(C.ROOT / "geometries" / "brake_pad.toml").replace(**{"mesh.maxh": PAD_MAXH})
    scratch = Path(tempfile.mkdtemp())
    mesh = build_mesh(pad, use_cache=False)
    mesh.ngmesh.Save(str(scratch / "pad.vol"))
    rows.append(part_rows(f"brake pad .vol (maxh {PAD_MAXH:g})", scratch / "pad.vol", "mesh", args.reps,
                          lambda: part_files._load_mesh(str(scratch / "pad.vol"))))
    rows[-1]["meshing_built_in_s"] = C.median([C.timed(build_mesh, pad, use_cache=False)[0]
                                               for _ in range(args.reps)])
    paper = ngwear.load_scene(C.PAPER)
    build_mesh(paper, use_cache=False).ngmesh.Save(str(scratch / "strip.vol"))
    rows.append(part_rows("paper strip .vol", scratch / "strip.vol", "mesh", args.reps,
                          lambda: part_files._load_mesh(str(scratch / "strip.vol"))))
    path, stat = scratch / "pad.vol", (scratch / "pad.vol").stat()
    sha = C.median([C.timed(_digest.__wrapped__, str(path), stat.st_size, stat.st_mtime_ns)[0]
                    for _ in range(args.reps)])
    steps = 2000 if args.quick else STEPS
    history = History.empty({"times": (), "rows": (ROW_BYTES // 8 - 1,)}, steps, scratch)
    history.buffers["rows"][:] = 1.0
    history.flush()
    crc = C.median([C.timed(lambda: History(history.buffers, history.folder).checksums(steps))[0]
                    for _ in range(args.reps)])
    rows.append({"part": f"resume: SHA-256 of pad mesh.vol / CRC-32 of {steps} rows", "size_mb": stat.st_size / 1e6,
                 "child_s": sha, "in_process_s": crc, "rows_gb": steps * ROW_BYTES / 1e9})
    for file in scratch.rglob("*.f64"):
        os.remove(file)
    header = C.machine_lines(args) + [
        "child: describe's child process (start, imports, read); in process: the same read here (before); "
        "extra = child - in process; mesh_or_read: Netgen meshing the STEP part, reading the .vol parts"]
    columns = [("part", "part", None), ("size_mb", "MB", ".3g"), ("child_s", "child s / SHA-256 s", ".3f"),
               ("in_process_s", "in process s / CRC-32 s", ".3f"), ("extra_s", "extra s", ".3f"),
               ("mesh_or_read_s", "mesh or read s", ".3f"), ("extra_share", "extra / mesh or read", ".0%"),
               ("meshing_built_in_s", "meshing the built-in pad s", ".2f"), ("rows_gb", "rows GB", ".2f")]
    C.finish("file_checks", "Checking files: parts in a child process, a resume's hashes", header, rows, columns,
             quick=args.quick)


if __name__ == "__main__":
    main()
