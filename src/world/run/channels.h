// channels.h: one list of an engine's output channels, by name and unit: the
// engine's row (sim.h's columns, engine_channels) followed by the channels
// its circuit publishes, generated from the compiled circuit: every node's
// pressure "<node>.p" [Pa], every valve's spool "<valve>.spool" [-] and every
// component's flow "<component>.q" [m^3/s] (a valve: "<valve>.qA" into A
// and "<valve>.qB" out of B). A new component's pressures and flows appear
// here, and in what reads the list (drive's charts and HUD, run --channels
// all), with no code that knows its name.
#ifndef CHANNELS_H
#define CHANNELS_H

#include "engine.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct chan_list chan_list;

/// The list for engine e (its circuit as it is now; the circuit's layout
/// never changes while the engine lives). NULL when out of memory.
chan_list* chan_list_create(engine* e);
void chan_list_free(chan_list* c);
/// Channels in all, and how many of them are the engine's row (the first).
int chan_list_count(const chan_list* c);
int chan_list_nrow(const chan_list* c);
/// Channel k (name, SI unit, kind), or NULL when out of range.
const sim_channel* chan_list_channel(const chan_list* c, int k);
/// Index of the channel named name, or -1.
int chan_list_find(const chan_list* c, const char* name);
/// Every channel's value now into out (chan_list_count entries): the row
/// (engine_row, whose t the caller may shift afterwards) and the circuit
/// evaluated at the engine's state (one circuit evaluation). Only the
/// circuit part when row_done: out's first chan_list_nrow entries are then
/// the caller's row and left as they are.
void chan_list_values(chan_list* c, engine* e, double* out, bool row_done);

#ifdef __cplusplus
}
#endif
#endif
