"""What every report page shares: the HTML shell, figure and table records, captions, colours and how values are drawn.
Each kind's page lives in its folder (``vibroimpact.kinds.<kind>.page``); :mod:`~vibroimpact.reporting.page` writes it."""
