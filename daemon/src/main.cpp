// Placeholder: neuflowd's entry point is being written.
int main() { return 0; }
