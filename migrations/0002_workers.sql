-- Workers by the name they claim with, and when each was last heard from (a claim, even one
-- that finds the queue empty, or a heartbeat). The jobs table alone cannot show an idle worker
-- polling an empty queue, nor one whose job failed or was handed back (both clear
-- jobs.worker), so the dashboard's list of workers needs its own rows. Times are Unix ms.
CREATE TABLE workers (
    name          TEXT PRIMARY KEY,
    first_seen_ms INTEGER NOT NULL,
    last_seen_ms  INTEGER NOT NULL
) WITHOUT ROWID;
CREATE INDEX workers_seen ON workers (last_seen_ms);
-- The jobs a worker holds, found by its name.
CREATE INDEX jobs_worker ON jobs (worker) WHERE state = 'leased';
