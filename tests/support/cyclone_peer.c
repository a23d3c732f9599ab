/* cyclone_peer: another vendor's DDS (Eclipse Cyclone DDS, C API, types from
 * our IDL compiled by its idlc) talking to a skelgraph graph
 * (tests/integration/cyclone_interop.sh).
 *
 *   cyclone_peer sub SECONDS         read skelgraph/skeleton/raw and skelgraph/sync
 *                                    for SECONDS; print what came as JSON
 *   cyclone_peer sync LABEL SESSION  act as a sync master: START, 30 TICKs at
 *                                    30 Hz, STOP on skelgraph/sync (once a reader
 *                                    matched); print what was sent as JSON
 *
 * The network comes from CYCLONEDDS_URI (the test keeps it on 127.0.0.1), the
 * domain from SKELGRAPH_DOMAIN (default 0), as for skelgraph. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dds/dds.h"
#include "skelgraph.h"

static int64_t now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

static dds_domainid_t domain(void) {
  const char* d = getenv("SKELGRAPH_DOMAIN");
  return d != NULL && *d != '\0' ? (dds_domainid_t)strtoul(d, NULL, 10) : 0;
}

static void check(dds_return_t rc, const char* what) {
  if (rc < 0) {
    fprintf(stderr, "cyclone_peer: %s: %s\n", what, dds_strretcode(rc));
    exit(1);
  }
}

/* A participant and the sync topic (reliable, keep-all QoS in *rel; the caller deletes it). */
static dds_entity_t sync_topic(dds_entity_t* pp, dds_qos_t** rel) {
  *pp = dds_create_participant(domain(), NULL, NULL);
  check(*pp, "participant");
  dds_entity_t t = dds_create_topic(*pp, &skelgraph_msg_SyncCommand_desc, "skelgraph/sync", NULL, NULL);
  check(t, "topic skelgraph/sync");
  *rel = dds_create_qos();
  dds_qset_reliability(*rel, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(*rel, DDS_HISTORY_KEEP_ALL, 0);
  return t;
}

static int sub(double seconds) {
  dds_entity_t pp;
  dds_qos_t* rel;
  dds_entity_t t_sync = sync_topic(&pp, &rel);
  dds_entity_t t_skel = dds_create_topic(pp, &skelgraph_msg_Skeleton_desc, "skelgraph/skeleton/raw", NULL, NULL);
  check(t_skel, "topic skelgraph/skeleton/raw");
  dds_qos_t* be = dds_create_qos();
  dds_qset_reliability(be, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(be, DDS_HISTORY_KEEP_LAST, 100);
  dds_entity_t r_skel = dds_create_reader(pp, t_skel, be, NULL);
  check(r_skel, "reader skeleton");
  dds_entity_t r_sync = dds_create_reader(pp, t_sync, rel, NULL);
  check(r_sync, "reader sync");

  unsigned long skeletons = 0, starts = 0, ticks = 0, stops = 0;
  char sensor[65] = "", label[129] = "";
  double head_y = 0.0;
  const int64_t end = now_ns() + (int64_t)(seconds * 1e9);
  while (now_ns() < end) {
    void* samples[16] = {0};
    dds_sample_info_t infos[16];
    int n = dds_take(r_skel, samples, infos, 16, 16);
    for (int i = 0; i < n; i++) {
      if (!infos[i].valid_data) continue;
      const skelgraph_msg_Skeleton* s = samples[i];
      if (skeletons++ == 0) {
        strncpy(sensor, s->sensor_id, sizeof(sensor) - 1);
        head_y = s->joints[0].position.y;
      }
    }
    if (n > 0) dds_return_loan(r_skel, samples, n);
    void* cmds[16] = {0};
    n = dds_take(r_sync, cmds, infos, 16, 16);
    for (int i = 0; i < n; i++) {
      if (!infos[i].valid_data) continue;
      const skelgraph_msg_SyncCommand* c = cmds[i];
      if (c->kind == skelgraph_msg_SYNC_START) {
        starts++;
        strncpy(label, c->label, sizeof(label) - 1);
      } else if (c->kind == skelgraph_msg_SYNC_TICK) {
        ticks++;
      } else if (c->kind == skelgraph_msg_SYNC_STOP) {
        stops++;
      }
    }
    if (n > 0) dds_return_loan(r_sync, cmds, n);
    dds_sleepfor(DDS_MSECS(5));
  }
  printf("{\"skeletons\": %lu, \"first_sensor\": \"%s\", \"first_head_y\": %.4f, "
         "\"sync\": {\"start\": %lu, \"tick\": %lu, \"stop\": %lu, \"label\": \"%s\"}}\n",
         skeletons, sensor, head_y, starts, ticks, stops, label);
  dds_delete_qos(be);
  dds_delete_qos(rel);
  dds_delete(pp);
  return 0;
}

static int sync_master(const char* label, unsigned session) {
  dds_entity_t pp;
  dds_qos_t* rel;
  dds_entity_t t_sync = sync_topic(&pp, &rel);
  dds_entity_t w = dds_create_writer(pp, t_sync, rel, NULL);
  check(w, "writer sync");
  /* Wait (at most 10 s) for a reader: our recorder. */
  dds_publication_matched_status_t st;
  const int64_t give_up = now_ns() + 10000000000LL;
  do {
    check(dds_get_publication_matched_status(w, &st), "matched status");
    if (st.current_count > 0) break;
    dds_sleepfor(DDS_MSECS(20));
  } while (now_ns() < give_up);
  if (st.current_count == 0) {
    fprintf(stderr, "cyclone_peer: no reader of skelgraph/sync matched within 10 s\n");
    return 1;
  }
  dds_sleepfor(DDS_MSECS(500)); /* let the other readers of the graph match too */
  skelgraph_msg_SyncCommand c;
  memset(&c, 0, sizeof(c));
  c.session_id = session;
  strncpy(c.label, label, sizeof(c.label) - 1);
  c.kind = skelgraph_msg_SYNC_START;
  c.master_stamp_ns = now_ns();
  check(dds_write(w, &c), "write START");
  unsigned long ticks = 0;
  for (; ticks < 30; ticks++) {
    dds_sleepfor(DDS_MSECS(33));
    c.kind = skelgraph_msg_SYNC_TICK;
    c.tick = ticks + 1;
    c.master_stamp_ns = now_ns();
    check(dds_write(w, &c), "write TICK");
  }
  c.kind = skelgraph_msg_SYNC_STOP;
  c.master_stamp_ns = now_ns();
  check(dds_write(w, &c), "write STOP");
  check(dds_wait_for_acks(w, DDS_SECS(5)), "acks");
  printf("{\"session_id\": %u, \"label\": \"%s\", \"ticks\": %lu, \"matched\": %d}\n", session, label, ticks,
         (int)st.current_count);
  dds_delete_qos(rel);
  dds_delete(pp);
  return 0;
}

int main(int argc, char** argv) {
  if (argc == 3 && strcmp(argv[1], "sub") == 0) return sub(atof(argv[2]));
  if (argc == 4 && strcmp(argv[1], "sync") == 0) return sync_master(argv[2], (unsigned)strtoul(argv[3], NULL, 10));
  fprintf(stderr, "usage: %s sub SECONDS | sync LABEL SESSION\n", argv[0]);
  return 2;
}
