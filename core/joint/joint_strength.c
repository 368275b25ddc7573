/*
 * joint_strength.c - what each joint is as strong as: its material's
 * fracture parameters, those of a joint set it lies on (a pre-existing
 * discontinuity, fdem_add_joint_set) and, where the parameters carry a
 * Weibull variation, a strength of its own drawn from that law.
 *
 * The joint loops read the constants through one index per joint into a
 * small table (joint_strength in model.h), as they read the material
 * before: a case without sets or variation has one entry per material,
 * holding the very numbers the material holds, so its results do not
 * change by a bit.
 *
 * The draws are counter-based: the joint on face F (its mesh vertices) of
 * part p, varied with seed s, takes the output of a splitmix64 stream
 * started at s at an index hashed from (p, F), a pure function of (s, p, F).
 * So a model owns no generator state, the draws do not depend on the order
 * or the thread that makes them, rebuilding a case from its document (as a
 * restart does) gives every joint the same strength, and neither the order
 * in which a mesh lists its elements nor the order in which the engine
 * numbers its joints moves a strength to another face. Keyed by the joint
 * index, as they were until 2026-11-24, the draws followed the numbering,
 * and the 3D joints' renumbering for speed had silently given a seed
 * another strength field.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "model/model.h"
#include "math/node_ids.h"
#include "joint.h"

/* -------------------------------------------------------------- draws */

/* Output `index` (0-based) of splitmix64 (Steele, Lea, Flood 2014) seeded
 * with `seed`: the state after index + 1 steps, mixed. */
static uint64_t splitmix64_at(uint64_t seed, uint64_t index)
{
    uint64_t z = seed + (index + 1) * 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* A Weibull variate of mean 1 and the given modulus m: scale
 * 1/Gamma(1 + 1/m) times (-ln U)^(1/m), U uniform in (0, 1) from the top 53
 * bits (half a unit off zero, so the factor is never 0 nor infinite). */
double weibull_factor(uint64_t seed, uint64_t index, double modulus)
{
    double u = ((double)(splitmix64_at(seed, index) >> 11) + 0.5) * 0x1.0p-53;
    return pow(-log(u), 1.0 / modulus) / tgamma(1.0 + 1.0 / modulus);
}

/* ---------------------------------------------------------- joint sets */

/* Faces are vertex triples (2D: the third is -1), each sorted, compared
 * lexicographically. */
static int face_compare(const void *pa, const void *pb)
{
    return node_ids_compare(pa, pb, 3);
}

static void face_key(const int32_t *vertices, int dim, int32_t key[3])
{
    key[2] = -1;
    for (int i = 0; i < dim; i++) key[i] = vertices[i];
    node_ids_sort(key, dim);
}

int fdem_add_joint_set(fdem_model *m, int part_index, const fdem_fracture_params *params,
                       const fdem_variation *variation, const int32_t *faces, int face_count,
                       fdem_error *err)
{
    int k = m->joint_set_count;
    fdem_variation none = {0, 0}, v = variation ? *variation : none;
    if (m->finalized || part_index < 0 || part_index >= m->part_count ||
        !m->parts[part_index].fracture) {
        model_error(err, FDEM_ITEM_PART, part_index,
                    m->finalized ? "the model is already finalized"
                                 : "joint set %d: part %d does not exist or does not fracture",
                    k, part_index);
        return -1;
    }
    if (!(params->tensile_strength > 0) || !(params->cohesion > 0) ||
        !(params->energy_I > 0) || !(params->energy_II > 0) ||
        !(params->friction_angle >= 0 && params->friction_angle < 90) ||
        !(v.weibull_modulus >= 0) || !isfinite(v.weibull_modulus)) {
        model_error(err, FDEM_ITEM_PART, part_index,
                    "joint set %d of part %d: strengths and energies must be > 0, the friction "
                    "angle in [0, 90) and the Weibull modulus finite and >= 0", k, part_index);
        return -1;
    }
    if (face_count < 1) {
        model_error(err, FDEM_ITEM_PART, part_index, "joint set %d of part %d has no faces", k,
                    part_index);
        return -1;
    }
    joint_set *sets = realloc(m->joint_sets, sizeof *sets * (size_t)(k + 1));
    int32_t *keys = malloc(sizeof(int32_t) * 3 * (size_t)face_count);
    if (sets) m->joint_sets = sets;
    if (!sets || !keys) {
        free(keys);
        model_error(err, FDEM_ITEM_PART, part_index, "out of memory for joint set %d", k);
        return -1;
    }
    for (int f = 0; f < face_count; f++)
        face_key(faces + (size_t)m->dim * (size_t)f, m->dim, keys + 3 * (size_t)f);
    qsort(keys, (size_t)face_count, 3 * sizeof(int32_t), face_compare);
    m->joint_sets[k] = (joint_set){part_index, *params, v, keys, face_count};
    m->joint_set_count++;
    return k;
}

void joint_sets_free(fdem_model *m)
{
    for (int k = 0; k < m->joint_set_count; k++) free(m->joint_sets[k].faces);
    free(m->joint_sets);
    m->joint_sets = NULL;
    m->joint_set_count = 0;
}

/* Joint j's part and face: the part's mesh vertices of its side A, sorted
 * (face_key), the same whatever element or copy they were reached from. */
static int joint_face(const fdem_model *m, int j, int32_t key[3])
{
    int part_index = m->elem_part[m->joint_elem[2 * j]];
    int begin = m->parts[part_index].node_begin;
    const int32_t *n = m->joint_node + 2 * (size_t)m->dim * (size_t)j;
    int32_t vertices[3];
    for (int i = 0; i < m->dim; i++) vertices[i] = m->node_origin[n[i]] - begin;
    face_key(vertices, m->dim, key);
    return part_index;
}

/* The index of joint j's draw: its part and face hashed through splitmix64
 * (a chain of outputs, each seeded with the one before), so that faces
 * that share vertices draw independently. */
static uint64_t joint_draw_index(const fdem_model *m, int j)
{
    int32_t key[3];
    uint64_t h = splitmix64_at(0, (uint64_t)joint_face(m, j, key));
    for (int i = 0; i < 3; i++) h = splitmix64_at(h, (uint64_t)(uint32_t)key[i]);
    return h;
}

/* The set joint j lies on (the last that names its face), or -1. */
static int joint_set_of(const fdem_model *m, int j)
{
    int32_t key[3];
    int part_index = joint_face(m, j, key);
    for (int k = m->joint_set_count - 1; k >= 0; k--) {
        const joint_set *s = &m->joint_sets[k];
        if (s->part == part_index &&
            bsearch(key, s->faces, (size_t)s->face_count, 3 * sizeof(int32_t), face_compare))
            return k;
    }
    return -1;
}

int joint_set_index(const fdem_model *m, int j) { return joint_set_of(m, j); }

/* ------------------------------------------------------------ the table */

/* The variation joint j's strengths take: its set's, else its material's. */
static const fdem_variation *joint_variation(const fdem_model *m, int j, int set)
{
    if (set >= 0) return &m->joint_sets[set].variation;
    return &m->materials[element_material(m, m->joint_elem[2 * j])].def.variation;
}

static joint_strength strength_of(const fdem_fracture_params *p)
{
    return (joint_strength){p->tensile_strength, p->cohesion,
                            tan(p->friction_angle * M_PI / 180), p->energy_I, p->energy_II};
}

/* Fills joint_strength_of and the table: entries 0 .. materials - 1 are
 * the materials' own (as joint_law_of read them before), then one per
 * joint set, then one per joint whose parameters vary. Needs joint_elem
 * and the element materials; fails when a joint set lies on no joint. */
int joint_strengths_assign(fdem_model *m, fdem_error *err)
{
    int J = m->joint_count, M = m->material_count, S = m->joint_set_count;
    int32_t *set_of = malloc(sizeof(int32_t) * (size_t)(J ? J : 1));
    int *used = calloc((size_t)(S ? S : 1), sizeof(int));
    m->joint_strength_of = malloc(sizeof(int32_t) * (size_t)(J ? J : 1));
    int ok = set_of && used && m->joint_strength_of;
    int varied = 0;
    for (int j = 0; ok && j < J; j++) {
        set_of[j] = S ? joint_set_of(m, j) : -1;
        if (set_of[j] >= 0) used[set_of[j]]++;
        varied += joint_variation(m, j, set_of[j])->weibull_modulus > 0;
    }
    for (int k = 0; ok && k < S; k++)
        if (!used[k]) {
            model_error(err, FDEM_ITEM_PART, m->joint_sets[k].part,
                        "joint set %d of part %d lies on no interior %s of the part", k,
                        m->joint_sets[k].part, m->dim == 3 ? "face" : "edge");
            free(set_of);
            free(used);
            return -1;
        }
    m->joint_strength_count = M + S + varied;
    m->joint_strengths = ok ? malloc(sizeof(joint_strength) * (size_t)m->joint_strength_count)
                            : NULL;
    if (!m->joint_strengths) {
        free(set_of);
        free(used);
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory for joints");
        return -1;
    }
    for (int k = 0; k < M; k++) {
        const material *mat = &m->materials[k];
        const fdem_fracture_params *fp = &mat->def.fracture;
        m->joint_strengths[k] = (joint_strength){fp->tensile_strength, fp->cohesion, mat->tan_phi,
                                                 fp->energy_I, fp->energy_II};
    }
    for (int k = 0; k < S; k++) m->joint_strengths[M + k] = strength_of(&m->joint_sets[k].params);
    int next = M + S;
    for (int j = 0; j < J; j++) {
        int mat = element_material(m, m->joint_elem[2 * j]);
        const fdem_variation *v = joint_variation(m, j, set_of[j]);
        int base = set_of[j] >= 0 ? M + set_of[j] : mat;
        if (!(v->weibull_modulus > 0)) {
            m->joint_strength_of[j] = base;
            continue;
        }
        double factor = weibull_factor(v->seed, joint_draw_index(m, j), v->weibull_modulus);
        m->joint_strengths[next] = m->joint_strengths[base];
        m->joint_strengths[next].tensile_strength *= factor;
        m->joint_strengths[next].cohesion *= factor;
        m->joint_strength_of[j] = next++;
    }
    free(set_of);
    free(used);
    return 0;
}
