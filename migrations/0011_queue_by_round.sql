-- Claim order: oldest campaign, then the jobs planned for the fewest units, then sample 0 of
-- every cell before sample 1. A cell that grows re-queues its samples with a larger plan; they
-- now wait until every other cell's first-round samples have been handed out, so the other
-- cells reach their first assessment instead of queueing behind the growing one.
DROP INDEX jobs_queue;
CREATE INDEX jobs_queue ON jobs (state, campaign_seq, units_planned, sample_index, cell_index);
