/*
 * vt_args.c - the option checks several vdsh programs share (vt_args.h).
 */
#include "vt_args.h"

#include <stdio.h>

#include "vt_cli.h"

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
        fprintf(stderr,
                "%s: %s: a part of a sharded bake (shard %u of %u): join the parts "
                "with vdsh-merge first\n",
                vt_cli_prog(), path, f->part.index, f->part.count);
        vdsh_free(f);
        return NULL;
    }
    return f;
}
