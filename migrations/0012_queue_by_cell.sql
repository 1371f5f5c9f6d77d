-- A campaign may ask for its cells one at a time (spec field `queue: "cells"`): each job's
-- queue_rank is then its cell index, otherwise 0, and the claim orders by it right after the
-- campaign, so a cell's growth rounds come before the next cell's first round. Rank 0 for
-- every job keeps the round order of migration 0011 for every other campaign.
ALTER TABLE jobs ADD COLUMN queue_rank INTEGER NOT NULL DEFAULT 0;
DROP INDEX jobs_queue;
CREATE INDEX jobs_queue ON jobs (state, campaign_seq, queue_rank, units_planned, sample_index, cell_index);
