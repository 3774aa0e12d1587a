/*
 * vt_json.h - JSON for every vdsh program, through cJSON.
 *
 * Purpose: the one way the programs write JSON (vdsh-bake --report,
 * vdsh-eval --json, vdsh-info --json, vdsh-view --bench) and read it
 * (vdsh-eval --bake-report): cJSON (Debian libcjson-dev) builds, escapes
 * and parses; this module adds what the documents need beyond it:
 *   strings    any bytes: invalid UTF-8 (a path given on the command line
 *              may hold any) becomes U+FFFD, so the output always parses
 *              as UTF-8 JSON; quotes, backslashes and control characters
 *              are escaped by cJSON
 *   numbers    exact: a float (f32) is printed with the fewest digits
 *              (6..9) that read back as the same float, a double with the
 *              fewest (15..17) that read back as the same double, whole
 *              numbers in full (64 bits, no rounding through a double)
 *   NaN, Inf   null (JSON has no non-finite numbers): e.g. a rate with
 *              nothing to count, an unmeasured time
 *   failures   an allocation that fails anywhere marks the document failed:
 *              it is then never printed half-built
 * Output is cJSON's formatted layout (tab indented), then a newline.
 *
 * Does not: define any document - each program keeps its own keys.
 *
 * Usage:
 *     vt_json j = {0};
 *     cJSON *root = vt_json_object(&j, NULL, NULL);
 *     vt_json_string(&j, root, "file", path);
 *     cJSON *v = vt_json_array(&j, root, "bounds");
 *     vt_json_f32(&j, v, NULL, 1.5f);            (array items: key NULL)
 *     if (vt_json_write_file(&j, "out.json", msg, sizeof msg)) ...error...
 *     vt_json_free(&j);
 * (bake/tools/vdsh_eval.c; tests/test_tools.c checks strings, numbers and the
 * reader.)
 *
 * Errors: vt_json_write_file and vt_json_write_stream return 0 or -1 with a
 * message naming the file; vt_json_read_file returns NULL with one.
 * Ownership: a vt_json owns its tree (vt_json_free; accepts a zeroed one);
 * the adders copy keys and strings. vt_json_read_file's tree is freed with
 * cJSON_Delete.
 * Threading: no shared state.
 */
#ifndef VT_JSON_H
#define VT_JSON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cjson/cJSON.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vt_json {
    cJSON *root;
    int failed; /* an allocation failed: nothing will be printed */
} vt_json;

/* Containers. parent NULL (and key NULL): the document's root, once.
 * Otherwise parent is an object (key names the member) or an array (key
 * NULL). Return NULL on failure; the adders accept a NULL parent (and then
 * only mark the document failed). */
cJSON *vt_json_object(vt_json *j, cJSON *parent, const char *key);
cJSON *vt_json_array(vt_json *j, cJSON *parent, const char *key);

/* Values. A NULL string is null. */
void vt_json_string(vt_json *j, cJSON *parent, const char *key, const char *s);
void vt_json_f32(vt_json *j, cJSON *parent, const char *key, float v);
void vt_json_f64(vt_json *j, cJSON *parent, const char *key, double v);
void vt_json_u64(vt_json *j, cJSON *parent, const char *key, uint64_t v);
void vt_json_i64(vt_json *j, cJSON *parent, const char *key, int64_t v);
void vt_json_bool(vt_json *j, cJSON *parent, const char *key, int v);
void vt_json_null(vt_json *j, cJSON *parent, const char *key);

/* The document as text ending in a newline (free() it); NULL if the
 * document failed or memory ran out. */
char *vt_json_print(vt_json *j);

/* The document to a file, atomically (formats/vdsh_output.h); or to an
 * open stream (stdout). 0, or -1 with a message in msg. */
/* path "-": stdout (vt_json_write_stream), the --json FILE convention. */
int vt_json_write_file(vt_json *j, const char *path, char *msg, size_t cap);
int vt_json_write_stream(vt_json *j, FILE *fp, const char *name, char *msg, size_t cap);

void vt_json_free(vt_json *j);

/* A whole file parsed (at most 64 MiB); NULL with a message ("PATH: cannot
 * open: ...", "PATH: not JSON (byte N)"). */
cJSON *vt_json_read_file(const char *path, char *msg, size_t cap);

/* The number at key of an object, or NAN when absent or not a number. */
double vt_json_number(const cJSON *object, const char *key);

#ifdef __cplusplus
}
#endif

#endif
