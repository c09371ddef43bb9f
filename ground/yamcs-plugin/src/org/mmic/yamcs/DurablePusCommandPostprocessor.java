package org.mmic.yamcs;

import java.io.UncheckedIOException;
import java.nio.file.Path;

import org.yamcs.YConfiguration;
import org.yamcs.YamcsServer;
import org.yamcs.commanding.PreparedCommand;
import org.yamcs.pus.PusCommandPostprocessor;

/**
 * YAMCS's {@link PusCommandPostprocessor} (length, sequence count, CRC) with sequence counts that survive a restart
 * of YAMCS ({@link DurableSeqCountFiller}). A link selects it with
 * {@code commandPostprocessorClassName: org.mmic.yamcs.DurablePusCommandPostprocessor}; the option
 * {@code seqCountFile} names the file (default {@code mmic-tc-seqcount.txt}; a relative name is under the
 * instance's directory in YAMCS's data directory). A count that cannot be saved fails the command, which is then
 * not sent.
 */
public class DurablePusCommandPostprocessor extends PusCommandPostprocessor {
    public static final String DEFAULT_FILE = "mmic-tc-seqcount.txt";

    @Override
    public void init(String yamcsInstance, YConfiguration config) {
        super.init(yamcsInstance, config);
        Path file = Path.of(config.getString("seqCountFile", DEFAULT_FILE));
        if (!file.isAbsolute()) {
            file = YamcsServer.getServer().getDataDirectory().resolve(yamcsInstance).resolve(file);
        }
        DurableSeqCountFiller filler = new DurableSeqCountFiller(file);
        seqFiller = filler;
        log.info("Telecommand sequence counts kept in {}", filler.file());
    }

    @Override
    public byte[] process(PreparedCommand pc) {
        try {
            return super.process(pc);
        } catch (UncheckedIOException e) {
            log.warn("{}", e.getMessage());
            failCommand(pc.getCommandId(), e.getMessage());
            return null;
        }
    }
}
