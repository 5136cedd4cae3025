"""Gmsh 2 (ASCII) mesh files written from plain lists, as the part-file tests need them."""


def write_msh(path, names, points, elements):
    """Write ``path`` and return it.

    ``names``: the physical groups (dim, tag, name); ``points``: (x, y, z), numbered from 1; ``elements``: (Gmsh
    type, physical tag, vertex numbers from 1), each in the elementary entity of its tag.
    """
    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(names)),
             *(f'{dim} {tag} "{name}"' for dim, tag, name in names), "$EndPhysicalNames",
             "$Nodes", str(len(points)), *(f"{i + 1} {x} {y} {z}" for i, (x, y, z) in enumerate(points)), "$EndNodes",
             "$Elements", str(len(elements)),
             *(f"{i + 1} {kind} 2 {tag} {tag} " + " ".join(map(str, vertices))
               for i, (kind, tag, vertices) in enumerate(elements)), "$EndElements"]
    path.write_text("\n".join(lines) + "\n")
    return path
