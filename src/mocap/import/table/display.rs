//! `TableLayout` as text, for `timpanist mocap columns`.

use super::*;

impl fmt::Display for TableLayout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let lines: Vec<String> = self.header_lines.iter().map(ToString::to_string).collect();
        writeln!(
            f,
            "delimiter {:?}, decimal {}, header line(s) {}{}, data from line {}",
            self.delimiter,
            if self.decimal_comma { "comma" } else { "point" },
            lines.join(", "),
            self.unit_line
                .map_or(String::new(), |u| format!(", unit row line {u}")),
            self.data_line
        )?;
        if !self.metadata.is_empty() {
            writeln!(f, "metadata:")?;
            for m in &self.metadata {
                writeln!(
                    f,
                    "  line {:>3}: {} = {}",
                    m.line,
                    m.key,
                    m.values.join(" | ")
                )?;
            }
        }
        writeln!(f, "columns:")?;
        for c in &self.columns {
            let unit = c.unit.as_deref().filter(|u| !u.is_empty());
            let unit = unit.map_or(String::new(), |u| format!(" [{u}]"));
            writeln!(
                f,
                "  #{:<4} {:<32}{unit} {}",
                c.index,
                format!("\"{}\"", c.name),
                c.first_value
            )?;
        }
        writeln!(f, "tracks:")?;
        for t in &self.tracks {
            let [x, y, z] = t.position;
            write!(f, "  {}: position #{x} #{y} #{z}", t.label)?;
            if let Some((kind, cols)) = &t.orientation {
                let cols: Vec<String> = cols.iter().map(|c| format!("#{c}")).collect();
                write!(f, ", {kind} {}", cols.join(" "))?;
            }
            writeln!(f)?;
        }
        for p in &self.problems {
            writeln!(f, "problem: {p}")?;
        }
        Ok(())
    }
}
