/*
 * cpca_tool.h - what the cpca measurement tools (cpca_widths_tool,
 * cpca_kchoice_tool) share: the stream they fit, looked up with the
 * reader's vdsh_find_stream.
 */
#ifndef VDSH_CPCA_TOOL_H
#define VDSH_CPCA_TOOL_H

#include "vdsh.h"

/* The fixed-order stream of `order` in a whole file (not a shard's part),
 * f32 at scale 1, of whichever quantity the bake stored; NULL when there
 * is none. */
static inline const vdsh_stream *cpca_tool_stream(const vdsh_file *f, uint32_t order)
{
    const vdsh_stream *found = NULL;
    for (uint32_t q = VDSH_QUANTITY_DISTANCE; !f->has_part && q <= VDSH_QUANTITY_LOG_DISTANCE;
         q++) {
        const vdsh_stream *s = vdsh_find_stream(f, order, q);
        if (s && s->encoding == VDSH_ENCODING_F32 && s->scale == 1.0f)
            found = s;
    }
    return found;
}

#endif
