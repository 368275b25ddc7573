/*
 * checkpoint.c - the dynamic state of a model as one flat byte buffer.
 *
 * Only what stepping changes is stored (step, time, step sizes, positions,
 * velocities, joint damage, the last contact detection, the stick springs,
 * energy accumulators, each joint's fracture account, the fracture
 * events not drained yet and the slip the joints' points keep): the static model is rebuilt from the case document,
 * so a checkpoint stays small and a model of another shape is detected by
 * its counts and refused. A model restored from a checkpoint steps on to the
 * same bits as the one that wrote it.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "model/model.h"
#include "checkpoint.h"
#include "contact/contact.h"
#include "element/element.h"
#include "fluid/fluid.h"
#include "joint/joint.h"
#include "step/step.h"

#define CHECKPOINT_MAGIC 0x31434446u /* "FDC1" */
#define CHECKPOINT_VERSION FDEM_CHECKPOINT_VERSION

/* Version 1 (fdemd 0.1): the header up to external_work, then positions,
 * velocities and damage. Read for cases stored by that version; they carry
 * on without friction history and restart their energy accounts' new terms
 * from zero. */
typedef struct checkpoint_header_v1 {
    uint32_t magic, version;
    int32_t nodes, elements, joints, constraints;
    int64_t step;
    double time, dt, dt_prev;
    double contact_work, damping_work, external_work;
} checkpoint_header_v1;

/* The energy accounts as a header holds them: fdem_energy as it was up to
 * version 7 (version 8 added `excavated`, which the stage section holds),
 * so the header keeps its layout. */
typedef struct checkpoint_energy {
    double kinetic, elastic, joint, contact, friction, fracture, damping, gravity_work,
        external_work, residual;
} checkpoint_energy;

static checkpoint_energy checkpoint_energy_of(const fdem_energy *e)
{
    return (checkpoint_energy){e->kinetic, e->elastic, e->joint, e->contact, e->friction,
                               e->fracture, e->damping, e->gravity_work, e->external_work,
                               e->residual};
}

static fdem_energy energy_of_checkpoint(const checkpoint_energy *c, double excavated)
{
    fdem_energy e = {0};
    e.kinetic = c->kinetic;
    e.elastic = c->elastic;
    e.joint = c->joint;
    e.contact = c->contact;
    e.friction = c->friction;
    e.fracture = c->fracture;
    e.damping = c->damping;
    e.gravity_work = c->gravity_work;
    e.external_work = c->external_work;
    e.residual = c->residual;
    e.excavated = excavated;
    return e;
}

/* Version 2 adds what makes a restored run continue bit for bit: the last
 * detection's positions and the largest displacement since (so detection
 * reruns at the same steps with the same pairs), the stick springs, and
 * every energy accumulator with the accounts as they stood. */
typedef struct checkpoint_header {
    checkpoint_header_v1 v1;
    double havg_last, friction_energy, fracture_energy;
    double max_disp2;
    int64_t detections;
    int32_t need_detect, has_detection;
    int64_t spring_records;
    int32_t has_viscous;
    int32_t dimension;       /* 0 in files written before 3D: 2 */
    checkpoint_energy energy; /* the accounts at the checkpoint, shown until the next step */
    /* version 3: the friction of intact joints (0 from a version 2 file,
     * written before joints booked any) */
    double joint_friction_energy;
    /* version 4: each joint's fracture account and the fracture events not
     * drained yet follow the stick springs (events.c). Version 5: the same
     * layout; 3D joints are numbered by their tetrahedra (joint_tet_model.c),
     * so an earlier file's 3D joint damage would land on other joints. */
    int64_t pending_events;
    /* version 6: time's compensation (model_time_after; 0 from earlier
     * files, whose time was summed plainly). Version 7: the same header;
     * the slip each joint point keeps (joint_law.h) follows the events.
     * Version 8: the same header; a model with stages has its stage
     * section (step/stages.c) after the slip. Version 9: the same header;
     * a model with fluid has its fluid section (fluid/fluid_checkpoint.c)
     * between the slip and the stages. Version 10: the same header; the
     * fluid section adds each constraint's injected volume. Version 11:
     * the same header; the fluid section adds each bore's fluid volume. */
    double time_carry;
} checkpoint_header;

/* The header of a version 2 file: everything before joint_friction_energy;
 * of a version 3 one, everything before pending_events. */
#define CHECKPOINT_HEADER_V2 offsetof(checkpoint_header, joint_friction_energy)
#define CHECKPOINT_HEADER_V3 offsetof(checkpoint_header, pending_events)
#define CHECKPOINT_HEADER_V5 offsetof(checkpoint_header, time_carry)

static int checkpoint_has_detection(const fdem_model *m) { return m->contact.enabled; }

/* Positions, velocities, damage, [detection positions], [viscous stresses],
 * stick springs. */
static size_t checkpoint_body_size(const fdem_model *m, int has_detection, int has_viscous,
                                   size_t spring_bytes)
{
    size_t D = (size_t)m->dim;
    return sizeof(double) * 2 * D * (size_t)m->node_count + sizeof(double) * (size_t)m->joint_count +
           (has_detection ? sizeof(double) * D * (size_t)m->node_count : 0) +
           (has_viscous ? sizeof(double) * (size_t)model_stress_comps(m) * (size_t)m->elem_count : 0) +
           spring_bytes;
}

/* The joints' slip (version 7), dim points a joint. */
static size_t checkpoint_slip_size(const fdem_model *m)
{
    return sizeof(joint_slip) * (size_t)m->dim * (size_t)m->joint_count;
}

size_t fdem_checkpoint_size(const fdem_model *m)
{
    return sizeof(checkpoint_header) +
           checkpoint_body_size(m, checkpoint_has_detection(m), m->elem_viscous != NULL,
                                contact_history_checkpoint_size(&m->contact)) +
           events_checkpoint_size(m) + checkpoint_slip_size(m) +
           fluid_checkpoint_size(m, CHECKPOINT_VERSION) + stages_checkpoint_size(m);
}

int fdem_checkpoint_write(const fdem_model *m, void *buf, size_t size)
{
    if (size < fdem_checkpoint_size(m)) return -1;
    size_t spring_bytes = contact_history_checkpoint_size(&m->contact);
    checkpoint_header h;
    memset(&h, 0, sizeof h);
    h.v1 = (checkpoint_header_v1){CHECKPOINT_MAGIC, CHECKPOINT_VERSION, m->node_count,
                                  m->elem_count, m->joint_count, m->constraint_count, m->step,
                                  m->time, m->dt, m->dt_prev, m->contact_work, m->damping_work,
                                  m->external_work};
    h.havg_last = m->havg_last;
    h.friction_energy = m->friction_energy;
    h.fracture_energy = m->fracture_energy;
    h.joint_friction_energy = m->joint_friction_energy;
    h.max_disp2 = m->contact.max_disp2;
    h.detections = m->contact.detections;
    h.need_detect = m->contact.need_detect;
    h.has_detection = checkpoint_has_detection(m);
    h.has_viscous = m->elem_viscous != NULL;
    h.dimension = m->dim;
    h.spring_records = (int64_t)(spring_bytes / contact_record_bytes(&m->contact));
    fdem_energy energy = fdem_get_energy(m);
    h.energy = checkpoint_energy_of(&energy);
    h.pending_events = m->event_count;
    h.time_carry = m->time_carry;
    unsigned char *p = buf;
    memcpy(p, &h, sizeof h);
    p += sizeof h;
    size_t nb = sizeof(double) * (size_t)m->dim * (size_t)m->node_count;
    size_t vb = sizeof(double) * (size_t)model_stress_comps(m) * (size_t)m->elem_count;
    memcpy(p, m->pos, nb);
    p += nb;
    memcpy(p, m->vel, nb);
    p += nb;
    if (m->joint_count) memcpy(p, m->joint_damage, sizeof(double) * (size_t)m->joint_count);
    p += sizeof(double) * (size_t)m->joint_count;
    if (h.has_detection) {
        memcpy(p, m->contact.pos_detect, nb);
        p += nb;
    }
    if (h.has_viscous) {
        memcpy(p, m->elem_viscous, vb);
        p += vb;
    }
    contact_history_checkpoint_write(&m->contact, p);
    p += spring_bytes;
    events_checkpoint_write(m, p);
    p += events_checkpoint_size(m);
    if (m->joint_count) memcpy(p, m->joint_slip, checkpoint_slip_size(m));
    p += m->joint_count ? checkpoint_slip_size(m) : 0;
    fluid_checkpoint_write(m, p);
    p += fluid_checkpoint_size(m, CHECKPOINT_VERSION);
    stages_checkpoint_write(m, p);
    return 0;
}

/* A damaged or hand-made header must not be restored: a negative step
 * would, for one, make the daemon drop every stored snapshot. */
static int checkpoint_header_sane(const checkpoint_header_v1 *h, fdem_error *err)
{
    const char *bad = NULL;
    if (h->step < 0) bad = "a negative step";
    else if (!isfinite(h->time) || h->time < 0) bad = "a time that is negative or not finite";
    else if (!isfinite(h->dt) || h->dt <= 0) bad = "a time step that is not positive and finite";
    else if (!isfinite(h->dt_prev) || h->dt_prev < 0) bad = "a previous time step that is negative or not finite";
    else if (!isfinite(h->contact_work) || !isfinite(h->damping_work) || !isfinite(h->external_work))
        bad = "energy totals that are not finite";
    if (!bad) return 0;
    model_error(err, FDEM_ITEM_NONE, -1,
                "checkpoint has %s (step %lld, t = %g s, dt = %g s); it is damaged",
                bad, (long long)h->step, h->time, h->dt);
    return -1;
}

int fdem_checkpoint_version(const void *buf, size_t size)
{
    checkpoint_header_v1 h1;
    if (size < sizeof h1) return -1;
    memcpy(&h1, buf, sizeof h1);
    if (h1.magic != CHECKPOINT_MAGIC || h1.version < 1 || h1.version > CHECKPOINT_VERSION)
        return -1;
    return (int)h1.version;
}

int fdem_checkpoint_read(fdem_model *m, const void *buf, size_t size, fdem_error *err)
{
    checkpoint_header_v1 h1;
    if (size < sizeof h1) {
        model_error(err, FDEM_ITEM_NONE, -1, "checkpoint is truncated (%zu bytes)", size);
        return -1;
    }
    memcpy(&h1, buf, sizeof h1);
    if (h1.magic != CHECKPOINT_MAGIC || h1.version < 1 || h1.version > CHECKPOINT_VERSION) {
        model_error(err, FDEM_ITEM_NONE, -1, "not an fdemd checkpoint (or of another version)");
        return -1;
    }
    if (h1.nodes != m->node_count || h1.elements != m->elem_count || h1.joints != m->joint_count ||
        h1.constraints != m->constraint_count) {
        model_error(err, FDEM_ITEM_NONE, -1,
                    "checkpoint is of a model with %d nodes, %d elements, %d joints; this one has "
                    "%d, %d, %d",
                    h1.nodes, h1.elements, h1.joints, m->node_count, m->elem_count, m->joint_count);
        return -1;
    }
    if (checkpoint_header_sane(&h1, err)) return -1;
    checkpoint_header h;
    memset(&h, 0, sizeof h);
    h.v1 = h1;
    size_t header = sizeof h1, expected;
    if (h1.version == 1) {
        expected = header + checkpoint_body_size(m, 0, 0, 0);
    } else {
        header = h1.version == 2 ? CHECKPOINT_HEADER_V2
               : h1.version == 3 ? CHECKPOINT_HEADER_V3
               : h1.version <= 5 ? CHECKPOINT_HEADER_V5
                                 : sizeof h;
        if (size < header) {
            model_error(err, FDEM_ITEM_NONE, -1, "checkpoint is truncated (%zu bytes)", size);
            return -1;
        }
        memcpy(&h, buf, header);
        if ((h.dimension ? h.dimension : 2) != m->dim) {
            model_error(err, FDEM_ITEM_NONE, -1, "checkpoint is of a %dD model; this one is %dD",
                        h.dimension ? h.dimension : 2, m->dim);
            return -1;
        }
        if (h1.version < 5 && m->dim == 3 && m->joint_count) {
            model_error(err, FDEM_ITEM_NONE, -1,
                        "checkpoint is of an earlier fdemd that numbered the 3D joints in "
                        "another order (version %u); run the case again from the start",
                        h1.version);
            return -1;
        }
        size_t record_bytes = contact_record_bytes(&m->contact);
        if (h.spring_records < 0 || h.spring_records > (int64_t)(size / record_bytes) ||
            h.has_detection != checkpoint_has_detection(m) ||
            h.has_viscous != (m->elem_viscous != NULL)) {
            model_error(err, FDEM_ITEM_NONE, -1, "checkpoint's contact section does not fit");
            return -1;
        }
        if (h.pending_events < 0 || h.pending_events > m->joint_count) {
            model_error(err, FDEM_ITEM_NONE, -1, "checkpoint's fracture events do not fit");
            return -1;
        }
        expected = header + checkpoint_body_size(m, h.has_detection, h.has_viscous,
                                                 (size_t)h.spring_records * record_bytes);
        if (h1.version >= 4)
            expected += sizeof(double) * (size_t)m->joint_count +
                        sizeof(fdem_event) * (size_t)h.pending_events;
        if (h1.version >= 7) expected += checkpoint_slip_size(m);
        if (h1.version >= 9) expected += fluid_checkpoint_size(m, h1.version);
    }
    /* the stage section's size depends on its ramps: it is checked as it
     * is read, and takes what follows the fixed part */
    size_t stage_bytes = h1.version >= 8 && m->stage_count && size > expected ? size - expected : 0;
    if (size != expected + stage_bytes || (h1.version >= 8 && m->stage_count && !stage_bytes)) {
        model_error(err, FDEM_ITEM_NONE, -1, "checkpoint has %zu bytes, expected %zu", size,
                    expected);
        return -1;
    }
    const unsigned char *p = (const unsigned char *)buf + header;
    const unsigned char *springs = p + checkpoint_body_size(m, h.has_detection, h.has_viscous, 0);
    if (contact_history_checkpoint_read(&m->contact, springs, (size_t)h.spring_records,
                                        m->elem_count)) {
        model_error(err, FDEM_ITEM_NONE, -1, "checkpoint's friction history is damaged");
        return -1;
    }
    /* before version 4 no joint's account was kept: a joint damaged then
     * reports only what it dissipates from now on when it breaks */
    if (m->joint_count) memset(m->joint_fracture, 0, sizeof(double) * (size_t)m->joint_count);
    m->event_count = 0;
    const unsigned char *events =
        springs + (size_t)h.spring_records * contact_record_bytes(&m->contact);
    if (h1.version >= 4 && events_checkpoint_read(m, events, h.pending_events)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory restoring fracture events");
        return -1;
    }
    /* before version 7 no joint kept its slip: a damaged joint takes it
     * from its sliding at the first step after the restart (the slide
     * beyond its elastic limit, which is what the law then measured) */
    if (m->joint_count) {
        if (h1.version >= 7)
            memcpy(m->joint_slip, events + events_checkpoint_size(m), checkpoint_slip_size(m));
        else
            memset(m->joint_slip, 0, checkpoint_slip_size(m));
    }
    const unsigned char *fluid = events + events_checkpoint_size(m) +
                                 (m->joint_count ? checkpoint_slip_size(m) : 0);
    size_t fluid_bytes = h1.version >= 9 ? fluid_checkpoint_size(m, h1.version) : 0;
    /* the stages before the counts below: they leave excavated joints out */
    size_t stage_used = 0;
    if (stage_bytes &&
        (stages_checkpoint_read(m, fluid + fluid_bytes, stage_bytes, &stage_used, err) ||
         stage_used != stage_bytes)) {
        if (stage_used != stage_bytes)
            model_error(err, FDEM_ITEM_NONE, -1, "checkpoint's stage section does not fit");
        return -1;
    }
    size_t nb = sizeof(double) * (size_t)m->dim * (size_t)m->node_count;
    size_t vb = sizeof(double) * (size_t)model_stress_comps(m) * (size_t)m->elem_count;
    memcpy(m->pos, p, nb);
    p += nb;
    memcpy(m->vel, p, nb);
    p += nb;
    if (m->joint_count) memcpy(m->joint_damage, p, sizeof(double) * (size_t)m->joint_count);
    p += sizeof(double) * (size_t)m->joint_count;
    m->step = h1.step;
    m->time = h1.time;
    m->time_carry = isfinite(h.time_carry) && fabs(h.time_carry) <= h1.dt ? h.time_carry : 0;
    m->dt = h1.dt;
    m->dt_prev = h1.dt_prev;
    m->contact_work = h1.contact_work;
    m->damping_work = h1.damping_work;
    m->external_work = h1.external_work;
    m->havg_last = h.havg_last;
    m->friction_energy = h.friction_energy;
    m->fracture_energy = h.fracture_energy;
    m->joint_friction_energy = h.joint_friction_energy;
    m->broken_joints = 0;
    for (int j = 0; j < m->joint_count; j++)
        m->broken_joints += m->joint_damage[j] >= 1.0 && !joint_is_excavated(m, j);
    if (m->joint_count || m->elem_active) m->fragments = joint_fragment_count(m);
    memset(m->force, 0, nb);
    m->fixed_valid = 0; /* computed again from the restored positions: the same bits */
    if (h1.version == 1 || !h.has_detection) {
        /* a model without contact never detects: its flag stays 0 as in a
         * fresh one, so a restarted run writes the same bytes */
        m->contact.need_detect = m->contact.enabled;
    } else {
        memcpy(m->contact.pos_detect, p, nb);
        p += nb;
        m->contact.need_detect = h.need_detect;
        m->contact.detections = h.detections;
    }
    if (h.has_viscous)
        memcpy(m->elem_viscous, p, vb);
    if (contact_restore_detection(m)) {
        model_error(err, FDEM_ITEM_NONE, -1, "out of memory restoring contact detection");
        return -1;
    }
    m->contact.max_disp2 = h.max_disp2;
    /* after the positions: pressures and apertures follow from them */
    if (fluid_bytes) fluid_checkpoint_read(m, fluid, h1.version);
    if (h1.version == 1) { /* no accounts stored: those of the restored positions */
        element_forces(m);
        memset(m->force, 0, nb);
        m->damping_work = h1.damping_work; /* that pass was no step */
        if (m->elem_viscous) memset(m->elem_viscous, 0, vb);
        m->restored_energy_valid = 0;
    } else {
        m->elastic_energy = h.energy.elastic;
        m->joint_energy = h.energy.joint;
        m->restored_energy = energy_of_checkpoint(&h.energy, m->excavated_energy);
        if (fluid_bytes) {
            m->restored_energy.fluid_work = m->fluid->restored_work;
            m->restored_energy.fluid_dissipation = m->fluid->dissipation;
        }
        m->restored_energy_valid = 1;
        energy_gravity_restored(m, h.energy.gravity_work);
    }
    return 0;
}
