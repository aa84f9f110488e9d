"""Reports: one page for a user's gear pair (``pair``) and the paper's figures with its
claims checked (``paper``)."""
