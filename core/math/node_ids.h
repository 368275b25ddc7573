/*
 * node_ids.h - a face or cell as the sorted list of its 2-4 node ids.
 *
 * Several checks find the same face or cell listed twice, or shared by two
 * elements, by sorting each one's node ids and the keys after them: joint
 * faces (joint_tet_model.c), joint sets (joint_strength.c), boundary
 * facets (boundary_load.c) and repeated mesh cells (proto/case/case_mesh.c).
 * Contract: node_ids_sort puts v[0 .. n) in increasing order;
 * node_ids_compare orders two such lists of n ids lexicographically
 * (-1, 0, 1), for qsort comparators that break ties their own way.
 */
#ifndef FDEM_NODE_IDS_H
#define FDEM_NODE_IDS_H

#include <stdint.h>

static inline void node_ids_sort(int32_t *v, int n)
{
    for (int i = 1; i < n; i++) /* insertion sort: n is at most 4 */
        for (int k = i; k > 0 && v[k - 1] > v[k]; k--) {
            int32_t t = v[k];
            v[k] = v[k - 1];
            v[k - 1] = t;
        }
}

static inline int node_ids_compare(const int32_t *a, const int32_t *b, int n)
{
    for (int i = 0; i < n; i++)
        if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
    return 0;
}

#endif /* FDEM_NODE_IDS_H */
