/* fill_only: no wire at all (intensity 0): fill colour or transparent. */

void main()
{
  write_output(0.0);
}
