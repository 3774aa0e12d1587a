/*
 * vt_args.c - the option checks several vdsh programs share (vt_args.h).
 */
#include "vt_args.h"

#include <stdio.h>

#include "vt_cli.h"

int vt_arg_u32(const char *option, const char *arg, uint32_t lo, uint32_t hi, uint32_t *out)
{
    if (vt_parse_u32(arg, lo, hi, out))
        return 1;
    vt_usage_error(vt_cli_prog(), "%s takes a whole number %u..%u, not '%s'", option,
                   (unsigned)lo, (unsigned)hi, arg);
    return 0;
}

int vt_arg_orders(const char *s, int distinct, int set[VDSH_ORDER_SLOTS])
{
    uint64_t v[VDSH_MAX_ORDER];
    int n = vt_parse_u64_list(s, 1, VDSH_MAX_ORDER, v, 1, VDSH_MAX_ORDER);
    int seen[VDSH_ORDER_SLOTS] = {0};
    for (int i = 0; i < n; i++) {
        if (distinct && seen[v[i]])
            return 0;
        seen[v[i]] = 1;
    }
    if (n == 0)
        return 0;
    for (int k = 0; k < VDSH_ORDER_SLOTS; k++)
        set[k] = seen[k];
    return 1;
}

const char *vt_arg_vdsh(int argc, char **argv, int first, const char *cmd, int more)
{
    const char *sep = cmd ? ": " : "";
    if (!cmd)
        cmd = "";
    if (first >= argc) {
        vt_usage_error(vt_cli_prog(), "%s%sno .vdsh file given", cmd, sep);
        return NULL;
    }
    if (!more && first + 1 < argc) {
        vt_usage_error(vt_cli_prog(), "%s%sone .vdsh file, not also '%s'", cmd, sep,
                       argv[first + 1]);
        return NULL;
    }
    return argv[first];
}

vdsh_file *vt_read_whole(const char *path)
{
    vdsh_file *f = NULL;
    vdsh_error err;
    if (vdsh_read(path, &f, &err) != VDSH_OK) {
        fprintf(stderr, "%s: %s\n", vt_cli_prog(), err.msg);
        return NULL;
    }
    if (f->has_part) {
        fprintf(stderr, "%s: %s: a part of a sharded bake (shard %u of %u): join the parts "
                        "with vdsh-merge first\n",
                vt_cli_prog(), path, f->part.index, f->part.count);
        vdsh_free(f);
        return NULL;
    }
    return f;
}
