"""The study: its trial design, seed, subject sheet and raw folder, which every stage's settings may take."""
