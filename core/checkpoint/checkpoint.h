/*
 * checkpoint.h - a model's whole state as bytes and back (checkpoint.c,
 * fdem_checkpoint_* in fdem.h): nodes, elements' history, joints, contact
 * springs, events, energy accounts, bit for bit, so that a restarted run
 * continues with the same bits. Reads older versions. Calls the stages
 * whose state it stores; nothing in core/ calls it.
 */
#ifndef FDEM_CHECKPOINT_H
#define FDEM_CHECKPOINT_H

#include "fdem.h"



#endif
