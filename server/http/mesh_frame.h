/*
 * mesh_frame.h - GET /cases/ID/mesh.bin[?snapshot=K][&fields=a,b]: one
 * snapshot's mesh, deformed positions and fields as the compact binary
 * frame the web page draws (docs/api.md, "Binary mesh frames").
 *
 * Contract: the frame is read on the I/O thread (io_read_frame), charged
 * to the request's memory lease while it is held; ?snapshot= is a
 * non-negative index (the last complete snapshot without it) and ?fields=
 * names from result_frame_field_names (all the file has without it),
 * ?surface= a flag, ?shape= 16 hex digits; a bad value is a 400 naming
 * it, a snapshot the case does not have a 404.
 */
#ifndef FDEMD_MESH_FRAME_H
#define FDEMD_MESH_FRAME_H

#include <microhttpd.h>

#include "cases/registry.h"

enum MHD_Result mesh_frame_reply(struct MHD_Connection *conn, server_case *c);

#endif
