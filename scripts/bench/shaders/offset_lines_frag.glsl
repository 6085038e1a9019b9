/* offset_lines: a covered line pixel is full wire intensity. */

void main()
{
  write_output(1.0);
}
