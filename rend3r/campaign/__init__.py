"""Campaigns: a pure task function mapped over many inputs, on a Dask distributed cluster
(in-process and sized to the machine by default, or an existing one) or serially
(:mod:`rend3r.campaign.runner`, ``docs/campaigns.md``)."""
