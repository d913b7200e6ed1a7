"""What users see beside the CLI: the HTML report and its cards, the review page, the feedback store."""
