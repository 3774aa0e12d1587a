/*
 * mesh.h - triangle meshes for the baker: loading OBJ/PLY/OFF/STL (strict
 * readers, mesh_parse.h), the built-in procedural scenes, welding, normals,
 * receiver refinement (OpenMesh, behind this C header) and OBJ output.
 *
 * Does not: trace rays or know about SH. Only mesh_refine.cpp includes
 * OpenMesh; it and the readers (C++) let no C++ exception escape.
 *
 * Usage (tests/test_mesh.c is a compiled example):
 *
 *     vb_mesh m = {0};
 *     vb_source_info info;
 *     vb_load_desc desc = {0};                (zero = documented defaults)
 *     if (vb_mesh_load("scene.obj", &desc, &m, &info, &err) != VB_OK) ...
 *     vb_mesh_report_print(stderr, "tool", "scene.obj", &info.report);
 *     vb_mesh fine = {0};
 *     vb_mesh_refine(&m, 0.2f, &fine, &err);  (receivers: no edge > 0.2)
 *     vb_mesh_free(&fine); vb_mesh_free(&m);
 *
 * Scene names: a path ending in .obj/.ply/.off/.stl/.gltf/.glb
 * (case-insensitive; glTF: bake/lib/mesh_gltf.cpp says what is read), or
 * "builtin:room" - the procedural paper-style room (19 x 6 x 19 m, y up,
 * boxes, pillars and a sphere; 1,518 vertices and 2,428 coarse triangles;
 * refine with vb_mesh_refine to make it dense: max edge 0.2 gives 58,007
 * receivers, the paper's scene had 54,500), or "builtin:room:N" for N = 1
 * .. 4294967295 (decimal, no leading zeros) - seeded variants of it, a
 * validation set of closed, furnished interiors of varied size and shape
 * (rectangle, L, split by a wall with a doorway; shelves, cabinets,
 * tables on thin legs, chairs, crates, thin screens and hanging sheets,
 * smooth spheres and cylinders; bake/builtin.c lists them), the same bytes
 * for the same N on any machine; at max edge 0.2 they give 20,000-80,000
 * receivers. Any other "builtin:" name fails with VB_ERR_ARGUMENT and a
 * message listing these.
 *
 * Loaded meshes are clean: triangles only (polygons fanned from their
 * first vertex where that fan lies inside them, every convex one; other
 * flat, simple polygons ear-clipped: mesh_read.h triangulate_polygon),
 * every index < vertex_count, no unreferenced vertices, every coordinate
 * finite, normals unit length or (0,0,0) where undefined (a vertex whose
 * faces all have zero area). Vertex normals come from the file when it has
 * them for every vertex (a zero one is replaced by the computed normal of
 * the vertex's own triangles), else are computed (angle-weighted face
 * normals over the vertex's own faces, so unwelded hard edges stay hard;
 * with vb_load_desc.crease, shared vertices split at sharp edges too).
 * Triangles with a repeated index are dropped (they have no area and no
 * effect on rays); zero-area triangles with distinct indices are kept.
 * Duplicate triangles are dropped: one with the same three positions as
 * an earlier kept triangle, in any corner order and either winding (a
 * receiver on one copy would see the other at distance ~0; rays hit
 * either alike), except the first reversed copy that shares no vertex with
 * it: the back of a two-sided sheet, whose vertices are its own receivers.
 * What was dropped, removed, split or repaired comes back as counts in
 * vb_source_info.report (vb_mesh_report); loading itself prints nothing.
 *
 * Normals per face corner (OBJ "f v//vn", "f v/vt/vn"; the other formats
 * give normals per vertex, and STL's facet normals are not read): a file
 * vertex whose corners give normals that disagree is split into one vertex
 * per normal, as the exporter meant (a floor and a wall sharing a position
 * at a crease keep a vertical and a horizontal normal; averaging them would
 * tilt both). Two corner normals agree when the angle between them is at
 * most VB_MESH_NORMAL_AGREE_DEG (0.1 degrees: any rounding of a printed
 * normal, 4 decimals ~0.006 degrees, welds; any crease meant, >= 1 degree,
 * splits). Each corner joins the first group of its vertex (in triangle
 * order) whose first normal it agrees with; a group's normal is that first
 * normal (unit length). A vertex whose corners all agree is not split and
 * keeps its normal as before (one given normal as is, several: their unit
 * average). Split vertices follow each other in the file's vertex order;
 * corners that give no normal, or a zero one, join the vertex's first
 * group. At most 256 groups per vertex; further disagreeing corners join
 * the closest.
 *
 * Files are read into memory once (vb_mesh_load_memory starts from such
 * bytes); those bytes are hashed for vb_source_info and read in one strict
 * pass straight into arrays (mesh_parse.h; no half-edge structure, so
 * non-manifold faces are kept as they are; duplicate faces are dropped,
 * as above, and counted). The readers read what OpenMesh 9's readers read (the
 * baker used those until issue 13: the same floats, vertex numbering and
 * normals, so the same bakes) and refuse what those would have skipped or
 * misread: numbers that do not parse or are NaN/Inf, faces with fewer than
 * 3 vertices, out-of-range indices, truncated files, counts that do not
 * fit the file, PLY list properties other than the faces' vertex_indices,
 * binary PLY coordinates, normals or texture coordinates of an integer
 * type and colours of type double, ascii PLY colours that are not whole
 * numbers of int range (unless typed float), OBJ "v" and face lines that
 * start with a vertical tab or form feed, OBJ face lines whose text after
 * '#' names further corners. What was read is cross-checked with what the
 * checks counted. OBJ: negative (relative) indices and TABs are fine;
 * materials and texture coordinates are ignored. STL: vertices with
 * identical positions are merged and triangles that then repeat a vertex
 * dropped, with or without `weld` (a file whose coordinates within FLT_MIN
 * of each other make that merge ambiguous is refused); an ascii STL must
 * end with "endsolid" (else it may have been cut between two facets), and
 * a solid whose name contains "outer" is refused (STL readers take that
 * line for the start of a facet).
 *
 * Errors: vb_result; messages name the file and the problem ("x.obj: line
 * 12: face index 40 out of range (30 vertices)", "x.ply: empty mesh").
 * Element numbers follow the format's own convention: 1-based for OBJ
 * (with the line), 0-based for PLY, OFF and STL triangles.
 *
 * Ownership: a vb_mesh owns its arrays; vb_mesh_free() frees them and
 * zeroes the struct; it accepts a zeroed or half-built mesh. Functions that
 * produce a mesh write *out only on success. Input meshes may have
 * normals == NULL (treated as undefined normals).
 *
 * Threading: no shared state in this module; loading runs concurrently.
 * vb_mesh_refine calls are serialised by one internal mutex, because
 * OpenMesh's log streams are process-wide: while one runs,
 * std::cerr/clog/cout are redirected (OpenMesh's warnings are discarded,
 * never printed); C stdio is not affected.
 */
#ifndef VB_MESH_H
#define VB_MESH_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "vb.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vb_mesh {
    uint32_t vertex_count;
    uint32_t triangle_count;
    float *positions;  /* 3 * vertex_count */
    float *normals;    /* 3 * vertex_count; unit, or 0,0,0 = undefined */
    uint32_t *indices; /* 3 * triangle_count */
} vb_mesh;

typedef struct vb_load_desc {
    /* 1: merge vertices with bit-identical positions (-0 and +0 count as
     * equal; normals then recomputed); 0 (default): keep the file's vertices */
    int weld;
    /* glTF: 0 (default) = the file's default scene (or its first); N + 1 =
     * scene N */
    int gltf_scene;
    /* the file's up axis, turned into +y first (every position and normal,
     * by an exact rotation: coordinates swapped and negated): 0 y (none,
     * the default), 1 z, 2 -z, 3 x, 4 -x, 5 -y (formats/vdsh.h,
     * VDSH_LOAD_UP_MASK; vdsh-bake --up-axis) */
    int up_axis;
    /* Crease angle for computed normals, in whole degrees: 0 (default) or
     * 180 and above = off. When the normals are computed (the file gives
     * none for some used vertex, or weld recomputed them), a vertex whose
     * triangles meet at an edge through it with face normals more than this
     * many degrees apart is split: one vertex per smooth fan (triangles
     * joined across its edges whose face normals are at most this far
     * apart), each with the normal of its own fan's triangles (so a cube's
     * 8 shared corners become 24 vertices with face normals at 60 degrees,
     * a sphere stays smooth). File normals are never changed. */
    int crease;
} vb_load_desc;

/* What loading found in a file and did about it, as counts (all zero for
 * the built-in scene and for a file with nothing to say). Counts of
 * vertices are of the file's vertices unless said otherwise. */
typedef struct vb_mesh_report {
    /* repeated a vertex index (no area), dropped; OBJ faces with fewer than
     * 3 distinct vertices count as their corners - 2 */
    uint32_t dropped_triangles;
    /* the same three positions as an earlier triangle (any corner order,
     * either winding), dropped; a reversed copy with vertices of its own (a
     * two-sided sheet's back) is kept */
    uint32_t duplicate_triangles;
    uint32_t removed_vertices; /* used by no remaining triangle */
    uint32_t split_vertices;   /* split at creases (corner normals) */
    uint32_t split_added;      /* vertices those splits added */
    /* used vertices with no file normal while others have one: all normals
     * computed */
    uint32_t missing_normals;
    /* loaded vertices whose file normal is zero (or whose given normals
     * cancel) */
    uint32_t zero_normals;
    /* of those, given their own triangles' normal */
    uint32_t zero_repaired;
    /* of those, whose triangles' normals cancel (two-sided): given their
     * largest triangle's normal */
    uint32_t zero_cancelled;
    /* of those, left (0,0,0): their triangles have no area (zero_repaired +
     * zero_cancelled + zero_undefined = zero_normals) */
    uint32_t zero_undefined;
    /* loaded vertices without a file normal whose computed normal cancelled
     * (two-sided triangles): given their largest triangle's normal */
    uint32_t cancelled_normals;
    uint32_t welded; /* vertices merged by weld */
    /* 1 when the normals were computed from the faces (no file normals, or
     * weld), so vb_load_desc.crease applies */
    uint32_t normals_computed;
    /* vb_load_desc.crease: vertices split at creases of the computed
     * normals, and the vertices those splits added */
    uint32_t crease_vertices;
    uint32_t crease_added;
    /* loaded vertices left (0,0,0) at the end: their triangles have no area
     * (those with a zero file normal included) */
    uint32_t undefined_normals;
    uint32_t gltf_skipped_modes; /* glTF: point and line primitives skipped */
    /* glTF: primitives with morph targets, baked in their base pose (targets
     * ignored; not skipped, despite the name) */
    uint32_t gltf_skipped_morph;
    /* glTF: primitives of skinned nodes, baked in their bind pose (not
     * skipped) */
    uint32_t gltf_skipped_skin;
    /* glTF: TRIANGLES primitives whose index (or vertex) count is not a
     * multiple of 3, the last 1 or 2 ignored */
    uint32_t gltf_ragged;
    /* faces of 4+ vertices whose triangles cover more than they enclose: not
     * simple or far from flat, so fanned, not ear-clipped; baked as fanned,
     * area outside the face included */
    uint32_t nonconvex_polygons;
    double nonconvex_excess; /* their fan area over their own, less 1 */
    /* the same, but fanned because the ear clipping's time bound ran out
     * (the file's other polygons spent it), not tried: not counted above */
    uint32_t unclipped_polygons;
    double unclipped_excess; /* their fan area over their own, less 1 */
} vb_mesh_report;

/* What a loaded source was: size and hash for the .vdsh SRCS chunk, and
 * what loading found. */
typedef struct vb_source_info {
    /* bytes of the file (or of the built-in arrays); for a glTF with
     * external buffers, the file's plus theirs */
    uint64_t size;
    uint8_t sha256[32]; /* of those bytes in that order (formats/VDSH.md) */
    uint64_t file_size; /* the file's bytes alone, and their SHA-256: */
    /* what bakes before 2026-11-30 recorded for a glTF with external buffers
     * (= size, sha256 for every other source) */
    uint8_t file_sha256[32];
    vb_mesh_report report;
} vb_source_info;

/* Corner normals within this angle (degrees) agree: see the top. */
#define VB_MESH_NORMAL_AGREE_DEG 0.1

/* One line per non-zero finding of `r` on fp, each "TOOL: PATH: ..."
 * (no "TOOL: " when tool is NULL), e.g. "vdsh-bake: scan.ply: 11160
 * triangles dropped (a repeated vertex index: no area)". A vertex is said
 * once: the zero file normals' line says what became of them (their own
 * triangles' normal, their largest triangle's, or none), and the lines on
 * cancelled and undefined normals count the other vertices only. Nothing
 * when fp is NULL (a tool's quiet mode) or nothing was found. */
void vb_mesh_report_print(FILE *fp, const char *tool, const char *path, const vb_mesh_report *r);

/* Load one file or built-in scene. `info` may be NULL. */
vb_result vb_mesh_load(const char *path, const vb_load_desc *desc, vb_mesh *out,
                       vb_source_info *info, vb_error *err);

/* Load receivers as they are (vdsh-bake --receivers: a plan): the mesh
 * vb_mesh_load gives with a zero desc, bit for bit. A binary PLY that
 * vb_mesh_write_ply wrote, whose mesh loading leaves as it is (positions
 * and normals finite, no zero normal, every face a triangle of three
 * distinct vertices, every vertex in a face: every plan vdsh-bake writes),
 * is read in one pass into the mesh's own arrays: its memory is the mesh's
 * (48 bytes per vertex with 2 triangles each), where vb_mesh_load holds the
 * file's bytes and the parser's arrays beside it (~5 times that). Any other
 * file: vb_mesh_load. */
vb_result vb_mesh_load_plan(const char *path, vb_mesh *out, vb_error *err);

/* Load a mesh file's bytes from memory (the fuzz targets' entry): exactly
 * as vb_mesh_load would load a file holding them. `name` only names the
 * bytes: it appears in messages and its extension (.obj/.ply/.off/.stl,
 * case-insensitive) picks the format; nothing is opened by that name and
 * "builtin:" names are refused. `data` is borrowed (may be NULL when size
 * is 0); `info` may be NULL. Nothing is written anywhere. */
vb_result vb_mesh_load_memory(const void *data, size_t size, const char *name,
                              const vb_load_desc *desc, vb_mesh *out, vb_source_info *info,
                              vb_error *err);

/* The built-in room, coarse (before refinement). */
vb_result vb_builtin_room(vb_mesh *out, vb_error *err);

/* Variant n of the room, coarse: builtin:room:n. VB_ERR_ARGUMENT for
 * n = 0. */
vb_result vb_builtin_room_variant(uint32_t n, vb_mesh *out, vb_error *err);

/* A built-in scene by its full name ("builtin:room", "builtin:room:7"), as
 * vb_mesh_load loads it; VB_ERR_ARGUMENT naming the known ones for any
 * other. */
vb_result vb_builtin_load(const char *name, vb_mesh *out, vb_error *err);

/* Append src to dst (indices offset); dst may be zeroed (empty). */
vb_result vb_mesh_append(vb_mesh *dst, const vb_mesh *src, vb_error *err);

/* Merge vertices with bit-identical positions (-0 == +0), keeping the
 * first of each in order; drop triangles that then repeat a vertex and
 * vertices no longer used; recompute normals. On failure (out of memory)
 * m is unchanged. */
vb_result vb_mesh_weld(vb_mesh *m, vb_error *err);

/* Recompute angle-weighted vertex normals from the triangles ((0,0,0)
 * for a vertex whose triangles all have zero area). Where the weighted sum
 * cancels (shorter than 1e-5 times the sum of its weights: a two-sided
 * triangle, a zero-width fold; what is left is rounding, pointing
 * anywhere) the vertex takes the unit normal of its largest triangle (the
 * first of equal ones). Allocates m->normals when it is NULL (and leaves
 * it NULL if that fails). */
void vb_mesh_compute_normals(vb_mesh *m);

/* Whether the triangle of corners ix (indices into positions, 3 floats a
 * vertex) has area: its cross product in double from the float corners
 * (exact: the differences and products of floats fit a double) is not
 * zero and finite - vb_mesh_compute_normals' own test, by which a vertex
 * whose triangles all fail it gets no computed normal. Such a triangle is
 * drawn nowhere: it covers no pixel, Embree never hits it, and the
 * evaluators' interior points, area weighted, never fall on it. */
int vb_triangle_has_area(const float *positions, const uint32_t *ix);

/* The drawn receivers: drawn[v] = 1 when one of the triangles around
 * vertex v has area (vb_triangle_has_area), else 0 - a receiver drawn
 * nowhere, whose origin the repair does not probe (origins.c) and whose
 * coefficients do not set the quantised scales
 * (vdsh_encode_quantised_drawn). Triangles with an index past
 * vertex_count are skipped. When no vertex is drawn (no triangle has
 * area), every one is marked drawn: then nothing is left out. Computed
 * from positions and triangles only, so vdsh-bake (its receivers) and
 * vdsh-merge (POSN, TRIS) agree. Returns the count marked drawn. */
uint32_t vb_drawn_receivers(const float *positions, uint32_t vertex_count, const uint32_t *indices,
                            uint32_t triangle_count, uint8_t *drawn);

/* Receiver refinement: split edges longer than max_edge (OpenMesh) until
 * none is; conforming (both triangles of an edge are split), deterministic,
 * no edge split that is already short enough. Original vertices keep their
 * indices; new vertices follow, with normals interpolated from the split
 * edge's ends and renormalised ((0,0,0) if they cancel). max_edge <= 0
 * copies the mesh.
 *
 * Longest edge first: the edge split next is the longest one left (ties:
 * lowest OpenMesh edge index), its length re-checked when it is taken, and
 * it is cut at its midpoint; each split halves the edge and joins the
 * midpoint to the opposite corner of each triangle on it. Within each
 * plane (faces whose normals agree within ~0.08 degrees) the triangulation
 * is kept Delaunay by edge flips (Lawson's: of the input, then around each
 * new vertex), so input slivers (long thin triangles) do not survive as
 * thinner ones: the result has about 1.5 - 2.5 vertices per max_edge^2 of
 * flat area and well-shaped triangles (vb_mesh_worst_aspect). Creases and
 * curved parts are not flipped (their shape is the surface). A mesh whose
 * edges are already <= max_edge comes back unchanged.
 *
 * Non-manifold input: a triangle OpenMesh's half-edge structure refuses
 * (third face on an edge, opposite orientation, complex vertex) is added
 * with its own copies of its three vertices (as OpenMesh's ImporterT does);
 * the copies are mapped back to the original indices afterwards and new
 * vertices with the same two parents (a shared edge split once per copy)
 * are merged, so the output stays conforming and no triangle is lost.
 * Triangles that repeat a vertex index have no area and are dropped
 * (except by the max_edge <= 0 copy).
 *
 * Cost: about 0.6 us per output vertex (builtin:room at 0.2: 58,007
 * vertices in ~35 ms; Sponza at 0.2: 1.08 M in ~1.1 s).
 *
 * Errors: VB_ERR_ARGUMENT for a NaN max_edge, when the input or the result
 * would have more than 2^24 vertices (checked from the surface area before
 * any work)
 * or when max_edge is below the float spacing of the coordinates (far from
 * the origin); VB_ERR_INVALID for an index out of range or a non-finite
 * position. */
vb_result vb_mesh_refine(const vb_mesh *in, float max_edge, vb_mesh *out, vb_error *err);

/* The worst aspect ratio of m's triangles: the longest edge squared over
 * the area, scaled so that the equilateral triangle is 1 (sqrt(3) L^2 /
 * (4 A); a right isosceles triangle is 1.73, a 10:1 sliver ~ 10). Triangles
 * without area (or with an index out of range) are skipped; 0 when none
 * has area. *worst (may be NULL) gets the triangle's number. */
double vb_mesh_worst_aspect(const vb_mesh *m, uint32_t *worst);

/* One level of chosen splits (adaptive receivers): split each edge
 * {pairs[2i], pairs[2i+1]} (vertex numbers of `in`) at its midpoint, both
 * its triangles (conforming), as vb_mesh_refine splits. The new vertex of
 * pair i is number in->vertex_count + i, its normal interpolated as there;
 * every other vertex keeps its number. A non-manifold edge (a refused
 * triangle's copy, coincident faces) is split in every triangle on it.
 * Errors: VB_ERR_ARGUMENT for a pair that is not an edge or is listed
 * twice; VB_ERR_INVALID for an index out of range. */
vb_result vb_mesh_split_edges(const vb_mesh *in, const uint32_t *pairs, uint32_t count,
                              vb_mesh *out, vb_error *err);

/* Write as OBJ (v, vn, f with v//vn; no vn when normals == NULL), with
 * enough digits (%.9g) that reading it back gives the same floats.
 * Atomically: a temporary file in the same directory, renamed over `path`
 * when complete; on failure no partial file is left and `path` keeps its
 * old content. */
vb_result vb_mesh_write_obj(const vb_mesh *m, const char *path, vb_error *err);

/* Write as binary little-endian PLY (x y z nx ny nz floats, triangles as
 * uchar-counted uint lists), read back bit for bit by vb_mesh_load;
 * atomically, as vb_mesh_write_obj. Needs normals. */
vb_result vb_mesh_write_ply(const vb_mesh *m, const char *path, vb_error *err);

/* The same two, staged (formats/vdsh_output.h): the file is written to a
 * temporary beside `path` and put on disk, not yet renamed, so that it
 * appears together with the files it goes with (vdsh-bake's --plan and
 * --export-obj with its .vdsh file): the caller then commits *out
 * (vdsh_output_commit) or removes it (vdsh_output_abort). On failure *out
 * is released (nothing left behind; abort accepts it). */
struct vdsh_output;
vb_result vb_mesh_stage_obj(const vb_mesh *m, const char *path, struct vdsh_output *out,
                            vb_error *err);
vb_result vb_mesh_stage_ply(const vb_mesh *m, const char *path, struct vdsh_output *out,
                            vb_error *err);

/* How far apart a mesh's vertices are, as receivers, relative to a
 * scene's size: each triangle's longest edge, weighted by the triangle's
 * area (a viewer sees surface, not triangle counts). VDSH interpolates the
 * stream between a triangle's corners, so a shadow edge is drawn no finer
 * than those edges; where they are long against the scene, shadows inside
 * the triangles are false (issue 26: an interior baked at its vertices,
 * false shadows on 39-51% of the lit area). vdsh-bake warns, without
 * --max-edge, --adaptive or --receivers, when more than
 * VB_SPACING_WARN_AREA of the area has longest edges above
 * VB_SPACING_WARN_EDGE of the scene's diagonal, and suggests --max-edge
 * VB_SPACING_SUGGEST of it. Measured (share of the area above 5%): the
 * built-in room 60% (its bake uses --max-edge 0.2, 0.7% of its diagonal),
 * Sponza 84%, Cornell box 100%, glTF 2CylinderEngine 50%, builtin:room:5
 * 12%, builtin:room:3 7%; dense meshes, which their vertices already
 * serve: Stanford bunnies, fandisk, Lost Empire 0%, rocker arm 2%. */
#define VB_SPACING_WARN_EDGE 0.05f
#define VB_SPACING_WARN_AREA 0.10
#define VB_SPACING_SUGGEST 0.01f

typedef struct vb_mesh_spacing {
    float diagonal; /* the scene diagonal the fractions are of */
    double area;    /* total triangle area */
    /* area-weighted median of the triangles' longest edges (within 2% of the
     * exact quantile) */
    float median_edge;
    float p90_edge; /* its 90th percentile (likewise) */
    float max_edge; /* the longest edge */
    /* share of the area (0..1) in triangles whose longest edge exceeds
     * VB_SPACING_WARN_EDGE x diagonal */
    double long_area;
    int far_apart; /* long_area > VB_SPACING_WARN_AREA */
    /* VB_SPACING_SUGGEST x diagonal, to 2 significant digits */
    float suggest_edge;
} vb_mesh_spacing;

/* The spacing of m's vertices against `diagonal` (<= 0: m's own bounds'
 * diagonal). One pass, no allocation. */
void vb_mesh_spacing_of(const vb_mesh *m, float diagonal, vb_mesh_spacing *s);

/* Axis-aligned bounds of all vertices; min = max = (0,0,0) when empty. */
void vb_mesh_bounds(const vb_mesh *m, float min[3], float max[3]);

void vb_mesh_free(vb_mesh *m);

/* SHA-256 of a byte buffer (used for source hashes): nettle's. `data`
 * may be NULL when size is 0. */
void vb_sha256(const void *data, size_t size, uint8_t out[32]);

#ifdef __cplusplus
}
#endif

#endif /* VB_MESH_H */
