/*
 * gmsh_internal.h - what gmsh.c (sections, nodes, elements, the mesh) and
 * gmsh_groups.c (physical groups) share while reading one file: the
 * line tokenizer, the reader state and its error reporting. Not a public
 * contract; gmsh.h is.
 *
 * Contract: every function that can fail returns -1 after gmsh_fail(),
 * which keeps the first message (with the section and line) and makes
 * later failures no-ops; nothing reads past r->end.
 */
#ifndef FDEM_GMSH_INTERNAL_H
#define FDEM_GMSH_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "gmsh.h"

#define GMSH_MAX_TOKENS 64 /* more than any element line we care about */
#define GMSH_TOKEN_CHARS 64

typedef struct gmsh_line {
    const char *tokens[GMSH_MAX_TOKENS];
    size_t lengths[GMSH_MAX_TOKENS];
    int count; /* tokens found (capped at GMSH_MAX_TOKENS) */
} gmsh_line;

typedef struct gmsh_node {
    long long tag;
    double x, y, z;
} gmsh_node;

typedef struct gmsh_element {
    long long tags[4];
    int line;
} gmsh_element;

/* What one dimension keeps: the gmsh element type, its node count, the
 * coordinates read per node, and the words of its messages. */
typedef struct gmsh_kind {
    int type, nodes, dims;
    const char *name;    /* "triangle" */
    const char *missing; /* the message when the file has none */
    int quadratic_type;  /* gmsh's second-order twin (6-node triangle, 10-node tetrahedron) */
    const char *only_quadratic; /* the message when the file has only those */
    int other_type;      /* the other dimension's linear element (tetrahedron, triangle) */
    const char *other;   /* the message when the file is a mesh of the other dimension */
} gmsh_kind;

/* An element of any type that may belong to physical groups: key is its
 * physical tag (2.2) or its entity's tag (4.1, whose entity lists the
 * physical tags). kept: its index among the kept elements, or -1; its
 * node tags are pool[first .. first + count). */
typedef struct gmsh_member {
    int dim;
    long long key;
    long kept;
    long first, count;
} gmsh_member;

/* A line of $PhysicalNames. */
typedef struct gmsh_physical {
    int dim;
    long long tag;
    char name[GMSH_NAME];
} gmsh_physical;

/* An entity of $Entities (4.1): its physical tags are pool[first ..]. */
typedef struct gmsh_entity {
    int dim;
    long long tag;
    long first, count;
} gmsh_entity;

typedef struct gmsh_reader {
    const char *p, *end;
    int line;              /* number of the line last read, 1-based */
    const char *section;   /* "$Nodes", ... for messages */
    int version;           /* 22 or 41 once $MeshFormat was read, else 0 */
    int seen_nodes, seen_elements;
    const gmsh_kind *kind;
    gmsh_node *nodes;
    long node_count, node_capacity;
    gmsh_element *elements;
    long element_count, element_capacity;
    long long quadratic_count; /* elements of kind->quadratic_type met */
    long long other_count;     /* elements of kind->other_type met */
    char *message;
    size_t message_size;
    int failed;
    /* physical groups, collected only when the caller wants them */
    int want_groups;
    gmsh_member *members;
    long member_count, member_capacity;
    long long *pool;
    long pool_count, pool_capacity;
    gmsh_physical *physicals;
    long physical_count, physical_capacity;
    gmsh_entity *entities;
    long entity_count, entity_capacity;
} gmsh_reader;

int gmsh_fail(gmsh_reader *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
int gmsh_next_line(gmsh_reader *r, gmsh_line *out);
int gmsh_need_line(gmsh_reader *r, gmsh_line *out, const char *what);
int gmsh_token_long(const gmsh_line *l, int i, long long *out);
int gmsh_line_longs(gmsh_reader *r, const gmsh_line *l, long long *out, int n, const char *what);
int gmsh_check_count(gmsh_reader *r, long long count, long min_bytes, const char *what);
int gmsh_grow(void **items, long *capacity, long need, size_t item_size);
/* Index of the node with this tag, from nodes sorted by tag, or -1. */
long gmsh_find_tag(const long *sorted, long n, const gmsh_node *nodes, long long tag);

/* gmsh_groups.c */
int gmsh_read_physical_names(gmsh_reader *r);
int gmsh_read_entities(gmsh_reader *r);
/* Notes the element of dimension dim (key as in gmsh_member) whose node
 * tags are tokens first .. of l; kept as in gmsh_member. */
int gmsh_note_element(gmsh_reader *r, int dim, long long key, const gmsh_line *l, int first,
                      long kept);
/* The dimension of a 2.2 element type, -1 for a type we do not know. */
int gmsh_type_dimension(long long type);
/* The named groups, with node indices through renumber[file index] (-1:
 * dropped) and kept elements through element_of[kept] (-1: a duplicate). */
int gmsh_resolve_groups(gmsh_reader *r, const long *sorted, const int32_t *renumber,
                        const long *element_of, gmsh_groups *out);
void gmsh_reader_free_groups(gmsh_reader *r);

#endif
